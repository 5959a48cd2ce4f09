"""Parses a LandXML file with Python's xml.etree (independent of tinsmith's reader) and
prints a summary as JSON: point and face counts, the first point (northing easting
elevation) and face, the surface type, EPSG code, linear unit and application name.

Usage: python3 tests/oracles/landxml_read.py FILE.xml
"""
import json
import sys
import xml.etree.ElementTree as ET

NS = {"lx": "http://www.landxml.org/schema/LandXML-1.2"}


def main():
    root = ET.parse(sys.argv[1]).getroot()
    assert root.tag == "{%s}LandXML" % NS["lx"], root.tag
    definition = root.find("lx:Surfaces/lx:Surface/lx:Definition", NS)
    points = definition.findall("lx:Pnts/lx:P", NS)
    faces = definition.findall("lx:Faces/lx:F", NS)
    crs = root.find("lx:CoordinateSystem", NS)
    units = root.find("lx:Units/*", NS)
    application = root.find("lx:Application", NS)
    by_id = {int(p.get("id")): [float(v) for v in p.text.split()] for p in points}
    out = {
        "points": len(points),
        "faces": len(faces),
        "surf_type": definition.get("surfType"),
        "first_point": by_id[1],
        "first_face": [int(v) for v in faces[0].text.split()],
        "epsg": crs.get("epsgCode") if crs is not None else None,
        "linear_unit": units.get("linearUnit"),
        "application": application.get("name") if application is not None else None,
        "date": root.get("date"),
        "version": root.get("version"),
    }
    json.dump(out, sys.stdout)


if __name__ == "__main__":
    main()
