#!/usr/bin/env bash
# Regenerates becmodel.npy: the sample DEM (data/becmodel_dem_bc_albers_50m.tif, Int16,
# nodata -32768) as a numpy array, read by GDAL once here so that the package's tests read
# it without GDAL. becmodel.json holds its geotransform and nodata value.
set -euo pipefail
cd "$(dirname "$0")"
tmp=$(mktemp -d) && trap 'rm -rf "$tmp"' EXIT
gdal_translate -q -of ENVI ../../../../data/becmodel_dem_bc_albers_50m.tif "$tmp/dem.raw"
"${PYTHON:-python3}" - "$tmp/dem.raw" <<'PY'
import json, subprocess, sys
import numpy as np
info = json.loads(subprocess.check_output(["gdalinfo", "-json", "../../../../data/becmodel_dem_bc_albers_50m.tif"]))
w, h = info["size"]
a = np.fromfile(sys.argv[1], dtype="<i2").reshape(h, w)
np.save("becmodel.npy", a)
band = info["bands"][0]
json.dump({"transform": info["geoTransform"], "nodata": band["noDataValue"]}, open("becmodel.json", "w"), indent=1)
PY
