"""An independent PNG reader for the preview tests: Pillow (PyPI, installed by
`make deps` into .venv).

Usage: .venv/bin/python3 tests/oracles/png_pixels.py FILE.png [X,Y ...]
Prints one JSON object: the image's mode, width and height, its text chunks, and the RGB
of each pixel asked for (in the order given).
"""

import json
import sys

from PIL import Image


def main():
    path, *points = sys.argv[1:]
    with Image.open(path) as image:
        image.load()
        rgb = image.convert("RGB")
        pixels = []
        for point in points:
            x, y = (int(v) for v in point.split(","))
            pixels.append(list(rgb.getpixel((x, y))))
        print(json.dumps({
            "mode": image.mode,
            "width": image.width,
            "height": image.height,
            "text": dict(image.text),
            "pixels": pixels,
        }))


if __name__ == "__main__":
    main()
