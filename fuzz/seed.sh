#!/usr/bin/env bash
# Fills fuzz/corpus/<target>/ (or DIR/<target>/ with `seed.sh DIR`) with seed inputs: the
# repository's test fixtures, the small mesh files committed in fuzz/seeds/, and tiny
# rasters cut from a raster fixture with gdal_translate (GDAL's command-line tools; skipped
# when missing). Existing corpus files (the fuzzer's own finds) are kept.
set -euo pipefail
fuzz="$(cd "$(dirname "$0")" && pwd)"
repo="$(dirname "$fuzz")"
corpus="${1:-$fuzz/corpus}"

# copy TARGET FILE...: copies each existing file into corpus/TARGET/.
copy() {
  local target=$1
  shift
  mkdir -p "$corpus/$target"
  for f in "$@"; do
    [ -f "$f" ] && cp "$f" "$corpus/$target/"
  done
  return 0
}

shopt -s nullglob
for target in read_ply read_obj read_stl read_glb read_geojson read_fgb read_landxml read_raster decimate; do
  mkdir -p "$corpus/$target"
  copy "$target" "$fuzz/seeds/$target"/*
done
copy read_ply "$repo"/crates/formats/tests/data/*.ply "$repo"/crates/formats/tests/malformed/*.ply
copy read_obj "$repo"/crates/formats/tests/data/*.obj "$repo"/crates/formats/tests/malformed/*.obj
copy read_raster "$repo"/crates/raster/tests/fixtures/*.{asc,tif} "$repo"/tests/fixtures/*.{tif,png}

# Tiny rasters of several drivers, types, nodata values, scales and masks.
if command -v gdal_translate >/dev/null; then
  src="$repo/crates/raster/tests/fixtures/landlab_hugo_site.asc"
  out="$corpus/read_raster"
  t() { gdal_translate -q -srcwin 30 20 8 6 "$@" >/dev/null 2>&1 || true; }
  t -of GTiff -ot Int16 -a_nodata -9999 "$src" "$out/i16_nodata.tif"
  t -of GTiff -ot Float32 -a_scale 0.5 -a_offset 100 "$src" "$out/f32_scaled.tif"
  t -of GTiff -ot Float64 -co COMPRESS=DEFLATE -co TILED=YES -co BLOCKXSIZE=16 \
    -co BLOCKYSIZE=16 "$src" "$out/f64_deflate.tif"
  t -of GTiff -ot Byte -scale -b 1 -b 1 -colorinterp_2 alpha "$src" "$out/byte_alpha.tif"
  t -of GTiff -ot UInt16 -a_nodata 65535 -a_srs EPSG:32633 "$src" "$out/u16_utm.tif"
  t -of AAIGrid "$src" "$out/small.asc"
  t -of PNG -ot Byte -scale "$src" "$out/small.png"
  t -of XYZ "$src" "$out/small.xyz"
  rm -f "$out"/*.aux.xml "$out"/*.prj "$out"/*.hdr
fi
for target in "$corpus"/*/; do
  echo "$(basename "$target"): $(find "$target" -type f | wc -l) seeds"
done
