"""What an image preview shows, as plain data: a sensor_msgs/Image or CompressedImage read from its CDR
(as the daemon's echo stream sends it; their layout is fixed, so no rclpy: header, then the sizes,
encoding and pixels, or the format and the compressed bytes), decoded and scaled with Pillow, and drawn
as lines of half blocks (``▀``: the upper pixel in the foreground colour, the lower one in the
background colour). No Textual here."""

from __future__ import annotations

import array
import io
from dataclasses import dataclass
from typing import cast

from rich.color import Color
from rich.style import Style
from rich.text import Text

from roc.cdr_reader import Reader
from roc.errors import RocError

IMAGE, COMPRESSED = "sensor_msgs/msg/Image", "sensor_msgs/msg/CompressedImage"
TYPES = (IMAGE, COMPRESSED)
# encoding -> (Pillow mode, Pillow raw mode, bytes per pixel); 16-bit and float images are scaled to their range
ENCODINGS = {
    "rgb8": ("RGB", "RGB", 3), "bgr8": ("RGB", "BGR", 3), "8UC3": ("RGB", "BGR", 3),
    "rgba8": ("RGBA", "RGBA", 4), "bgra8": ("RGBA", "BGRA", 4), "8UC4": ("RGBA", "BGRA", 4),
    "mono8": ("L", "L", 1), "8UC1": ("L", "L", 1),
    "mono16": ("I;16", "I;16", 2), "16UC1": ("I;16", "I;16", 2), "32FC1": ("F", "F;32F", 4),
}


@dataclass
class Picture:
    """An image message, decoded: Pillow's image and what the title says of it."""

    image: object  # PIL.Image.Image
    description: str  # "640x480 rgb8" or "jpeg 640x480"


def picture(type_name: str, cdr: bytes) -> Picture:
    """The image of a message of ``type_name`` (one of TYPES) given as CDR; RocError for one it cannot show."""
    from PIL import Image, UnidentifiedImageError
    from PIL.Image import DecompressionBombError

    reader = Reader(cdr, "image")
    reader.number("i"), reader.number("I"), reader.text()  # header: stamp, frame_id
    try:
        if type_name == COMPRESSED:
            image_format = reader.text()
            decoded = Image.open(io.BytesIO(reader.raw()))
            decoded.load()
            return Picture(decoded, f"{image_format or decoded.format} {decoded.width}x{decoded.height}")
        height, width, encoding = int(reader.number("I")), int(reader.number("I")), reader.text()
        big_endian, step = reader.number("B"), int(reader.number("I"))
        data = reader.raw()
    except (UnidentifiedImageError, DecompressionBombError, OSError) as error:
        raise RocError(f"cannot read the image: {error}") from None
    if encoding not in ENCODINGS:
        raise RocError(f"encoding '{encoding}' is not previewed (only {', '.join(ENCODINGS)})")
    mode, raw_mode, size = ENCODINGS[encoding]
    if width == 0 or height == 0 or step < width * size or len(data) < step * height:
        raise RocError(f"a {width}x{height} {encoding} image with {len(data)} bytes of step {step} is inconsistent")
    if big_endian and size > 1:  # Pillow's 16-bit and float images are little-endian: the bytes swapped here
        words = array.array("H" if size == 2 else "f", data[:len(data) - len(data) % size])
        words.byteswap()
        data = words.tobytes()
    image = Image.frombuffer(mode, (width, height), data, "raw", raw_mode, step, 1)
    if mode in ("I;16", "F"):  # depth or thermal: scaled to the image's own range
        low, high = cast(tuple[float, float], image.getextrema())  # one band
        span = (high - low) or 1
        image = image.convert("F").point(lambda value: (value - low) * 255.0 / span).convert("L")
    return Picture(image, f"{width}x{height} {encoding}")


def half_blocks(image, columns: int, rows: int) -> list[Text]:
    """``image`` scaled to fit ``columns`` x ``rows`` terminal cells (two pixels a cell, one above the
    other: about square pixels), its aspect kept, as lines of ``▀``."""
    from PIL import Image

    columns, rows = max(1, columns), max(1, rows)
    scale = min(columns / image.width, 2 * rows / image.height)
    width, height = max(1, round(image.width * scale)), max(2, round(image.height * scale))
    # larger: each pixel a block of cells (no blur); smaller: each cell the average of its pixels
    resample = Image.Resampling.NEAREST if scale >= 1 else Image.Resampling.BOX
    pixels = image.convert("RGB").resize((width, height + height % 2), resample)
    data = pixels.load()
    styles: dict[tuple, Style] = {}
    lines = []
    for row in range(0, pixels.height, 2):
        line = Text()
        for column in range(width):
            colours = (data[column, row], data[column, row + 1])
            style = styles.get(colours)
            if style is None:
                style = styles[colours] = Style(color=Color.from_rgb(*colours[0]), bgcolor=Color.from_rgb(*colours[1]))
            line.append("▀", style)
        lines.append(line)
    return lines


GRID = "nav_msgs/msg/OccupancyGrid"


def grid_image(grid: dict, columns: int, rows: int):
    """A decoded nav_msgs/OccupancyGrid as a Pillow image for ``half_blocks`` in ``columns`` x ``rows``
    cells: free white, occupied black (the likelier, the darker), unknown grey, north up (the grid's
    first row is its bottom). Shrunk to the cells, a cell takes its darkest cell of the map, so that a
    wall one cell thick stays drawn."""
    from PIL import Image, ImageFilter

    info = grid["info"]
    width, height = info["width"], info["height"]
    if not width or not height or len(grid["data"]) < width * height:
        raise RocError(f"an empty or short grid ({width} x {height}, {len(grid['data'])} cells)")
    shades = bytes(128 if value < 0 else 255 - min(value, 100) * 255 // 100 for value in grid["data"][:width * height])
    image = Image.frombytes("L", (width, height), shades).transpose(Image.Transpose.FLIP_TOP_BOTTOM)
    shrink = max(width / max(1, columns), height / (2 * max(1, rows)))
    if shrink > 1.5:
        image = image.filter(ImageFilter.MinFilter(2 * int(shrink / 2) + 1))
    return image
