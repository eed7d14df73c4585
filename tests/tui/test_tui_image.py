"""roc tui's image preview: sensor_msgs Image and CompressedImage read from their CDR and drawn in half
blocks (roc.tui.images), and the image screen (``i`` on a topic, ``:image TOPIC``) on real rclpy
publishers, the newest frame at most twice a second (echo's ``latest_every``)."""

from __future__ import annotations

import asyncio
import io
import struct
import time

import pytest
from helpers.graph import graph_env
from helpers.tui import SIZE, live_graph, open_row, palette_command, screen_name, until
from PIL import Image as Pillow
from rclpy.serialization import serialize_message
from sensor_msgs.msg import CompressedImage, Image

from roc.errors import RocError
from roc.tui.app import RocApp
from roc.tui.images import COMPRESSED, IMAGE, half_blocks, picture

RED, BLUE, GREEN = (255, 0, 0), (0, 0, 255), (0, 255, 0)


def png(width: int, height: int, colour: tuple[int, int, int]) -> bytes:
    written = io.BytesIO()
    Pillow.new("RGB", (width, height), colour).save(written, "PNG")
    return written.getvalue()


def raw(encoding: str, width: int, height: int, data: bytes, big_endian: int = 0) -> bytes:
    return serialize_message(Image(height=height, width=width, encoding=encoding, is_bigendian=big_endian,
                                   step=len(data) // height, data=data))


def colours(image) -> list[tuple[int, ...]]:
    rgb = image.convert("RGB")
    return [rgb.getpixel((x, y)) for y in range(rgb.height) for x in range(rgb.width)]


@pytest.mark.parametrize(("encoding", "data", "expected"), [
    ("rgb8", bytes([*RED, *BLUE]), [RED, BLUE]),
    ("bgr8", bytes([*RED[::-1], *BLUE[::-1]]), [RED, BLUE]),
    ("bgra8", bytes([*RED[::-1], 255, *BLUE[::-1], 255]), [RED, BLUE]),
    ("mono8", bytes([0, 255]), [(0, 0, 0), (255, 255, 255)]),
    ("mono16", struct.pack("<2H", 1000, 3000), [(0, 0, 0), (255, 255, 255)]),  # scaled to its own range
    ("32FC1", struct.pack("<2f", 0.5, 2.5), [(0, 0, 0), (255, 255, 255)]),
])
def test_raw_images_of_each_encoding_are_decoded(encoding: str, data: bytes, expected: list) -> None:
    found = picture(IMAGE, raw(encoding, 2, 1, data))
    assert colours(found.image) == expected and found.description == f"2x1 {encoding}"


def test_a_big_endian_depth_image_and_a_compressed_one_are_decoded() -> None:
    assert colours(picture(IMAGE, raw("16UC1", 2, 1, struct.pack(">2H", 7, 1), 1)).image) == [(255,) * 3, (0,) * 3]
    found = picture(COMPRESSED, serialize_message(CompressedImage(format="png", data=png(3, 2, GREEN))))
    assert colours(found.image) == [GREEN] * 6 and found.description == "png 3x2"


@pytest.mark.parametrize(("type_name", "message", "error"), [
    (IMAGE, raw("yuv422", 2, 1, bytes(4)), "encoding 'yuv422' is not previewed"),
    (IMAGE, serialize_message(Image(height=2, width=2, encoding="rgb8", step=6, data=bytes(6))), "inconsistent"),
    (COMPRESSED, serialize_message(CompressedImage(format="jpeg", data=b"not a jpeg")), "cannot read the image"),
])
def test_an_image_that_cannot_be_shown_says_why(type_name: str, message: bytes, error: str) -> None:
    with pytest.raises(RocError, match=error):
        picture(type_name, message)


def test_half_blocks_keep_the_aspect_two_pixels_a_cell() -> None:
    image = Pillow.new("RGB", (4, 2), RED)
    image.paste(BLUE, (2, 0, 4, 2))  # the right half blue
    lines = half_blocks(image, 80, 10)  # 4x2 pixels into 80 columns: 20 times larger, 40 pixels high
    assert len(lines) == 10 and {line.cell_len for line in lines} == {40}
    assert {str(line) for line in lines} == {"▀" * 40}
    assert {(span.style.color.triplet, span.style.bgcolor.triplet) for line in lines for span in line.spans} == {
        (RED, RED), (BLUE, BLUE)}  # pixels enlarged, not blurred
    styles = lines[0].spans
    assert (styles[0].style.color.triplet, styles[0].style.bgcolor.triplet) == (RED, RED)
    assert styles[-1].style.bgcolor.triplet == BLUE


CAMERA = [[{"name": "camera", "publishers": [
    {"topic": "camera/image_raw", "type": "sensor_msgs/msg/Image", "rate_hz": 20,
     "values": {"height": 2, "width": 4, "encoding": "rgb8", "step": 12, "data": [*RED, *RED, *BLUE, *BLUE] * 2}},
    {"topic": "camera/compressed", "type": "sensor_msgs/msg/CompressedImage", "rate_hz": 5,
     "values": {"format": "png", "data": list(png(4, 2, GREEN))}},
    {"topic": "chatter", "type": "std_msgs/msg/String", "values": {"data": "hi"}, "rate_hz": 5}]}]]


@pytest.fixture(scope="module")
def graph(tmp_path_factory):
    with live_graph(graph_env(66, tmp_path_factory.mktemp("runtime")), CAMERA) as env:
        yield env


def drawn_colours(app) -> set[tuple]:
    """The (foreground, background) colours of the half blocks on the image screen, as drawn."""
    image = app.screen.query_one("#image")
    found = set()
    for y in range(image.size.height):
        for segment in image.render_line(y):
            if "▀" in segment.text and segment.style is not None:
                found.add((segment.style.color.triplet, segment.style.bgcolor.triplet))
    return found


@pytest.mark.slow
def test_an_image_topic_drawn_live_paused_and_a_compressed_one_from_the_palette(graph) -> None:
    async def test() -> None:
        app = RocApp()
        async with app.run_test(size=SIZE) as pilot:
            await open_row(app, pilot, "topics", "/camera/image_raw")
            await until(pilot, lambda: screen_name(app) == "TopicScreen" and app.screen.type_name == IMAGE,
                        what="the topic and its type")
            started = time.monotonic()  # before the screen's stream starts
            await pilot.press("i")
            await until(pilot, lambda: screen_name(app) == "ImageScreen", what="the image screen")
            screen = app.screen
            await until(pilot, lambda: screen.frames >= 3, what="three frames")
            assert drawn_colours(app) == {(RED, RED), (BLUE, BLUE)}
            assert "4x2 rgb8" in str(screen.query_one("#title").render())
            # 20 images a second published, at most two a second sent by the daemon
            assert screen.received <= 2 * (time.monotonic() - started) + 2
            await pilot.press("space")
            paused = screen.frames
            await until(pilot, lambda: screen.received >= paused + 2, what="images while paused")
            assert screen.frames == paused and "paused" in str(screen.query_one("#title").render())
            await pilot.press("escape", "escape")
            await until(pilot, lambda: screen_name(app) == "GraphScreen", what="the first screen")
            await palette_command(app, pilot, "image /camera/compressed")
            await until(pilot, lambda: screen_name(app) == "ImageScreen" and app.screen.frames >= 1, what="a png")
            assert drawn_colours(app) == {(GREEN, GREEN)}
            await pilot.press("escape")
            await open_row(app, pilot, "topics", "/chatter")
            await until(pilot, lambda: screen_name(app) == "TopicScreen" and app.screen.type_name is not None)
            await pilot.press("i")  # no image: said, and the topic stays
            await until(pilot, lambda: any("is no image, scan or grid topic" in str(n.message) for n in app._notifications),
                        what="the warning")
            assert screen_name(app) == "TopicScreen"
    asyncio.run(test())
