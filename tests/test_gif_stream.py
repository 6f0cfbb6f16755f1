"""The animated GIF written frame by frame: frames, sizes, colours, delays and looping as a GIF
reader (Pillow) sees them, and the bytes the GIF format fixes."""

from __future__ import annotations

import io
import struct

import numpy as np
import pytest
from PIL import Image

from studio.core.files.gif_stream import GifStream

pytestmark = pytest.mark.core

RED, GREEN, BLUE, WHITE = (255, 0, 0), (0, 255, 0), (0, 0, 255), (255, 255, 255)


def flat(colour: tuple[int, int, int], height: int = 4, width: int = 5) -> np.ndarray:
    """A frame of one colour."""
    frame = np.empty((height, width, 3), np.uint8)
    frame[:] = colour
    return frame


def quadrants(height: int, width: int) -> np.ndarray:
    """Four flat colours, one per quadrant (a few colours survive quantisation exactly)."""
    frame = flat(RED, height, width)
    frame[: height // 2, width // 2:] = GREEN
    frame[height // 2:, : width // 2] = BLUE
    frame[height // 2:, width // 2:] = WHITE
    return frame


def write(frames: list[np.ndarray], delay_ms: float = 40.0) -> tuple[bytes, GifStream]:
    """The GIF bytes of the frames, and the stream that wrote them."""
    handle = io.BytesIO()
    stream = GifStream(handle, delay_ms)
    for frame in frames:
        stream.add(frame)
    stream.close()
    assert not handle.closed  # the owner closes the handle
    return handle.getvalue(), stream


def decode(data: bytes) -> tuple[list[np.ndarray], list[int], int | None]:
    """(RGB frames, durations in ms, loop count) as Pillow reads the GIF."""
    frames, durations = [], []
    with Image.open(io.BytesIO(data), formats=["GIF"]) as img:
        loop = img.info.get("loop")
        for index in range(img.n_frames):
            img.seek(index)
            frames.append(np.asarray(img.convert("RGB")))
            durations.append(img.info["duration"])
    return frames, durations, loop


def test_frames_come_back_in_order_with_their_colours_and_delay() -> None:
    """Each distinct frame is one GIF frame, pixel-exact for flat colours, with its delay."""
    frames = [flat(RED), flat(GREEN), flat(BLUE), quadrants(4, 5)]
    data, stream = write(frames, 40.0)
    decoded, durations, loop = decode(data)
    assert stream.frames == 4
    assert len(decoded) == 4
    for got, want in zip(decoded, frames, strict=True):
        assert got.shape == (4, 5, 3)
        assert np.array_equal(got, want)
    assert durations == [40, 40, 40, 40]
    assert loop == 0  # for ever
    assert data.endswith(b"\x3b")


def test_tall_and_wide_frames_keep_their_pixels() -> None:
    """Frames 16 pixels or more each way (which Pillow writes interlaced) decode exactly."""
    frames = [quadrants(18, 16), flat(GREEN, 18, 16), quadrants(18, 16)[::-1].copy()]
    data, stream = write(frames, 100.0)
    decoded, durations, _ = decode(data)
    assert stream.frames == 3
    assert [frame.shape for frame in decoded] == [(18, 16, 3)] * 3
    for got, want in zip(decoded, frames, strict=True):
        assert np.array_equal(got, want)
    assert durations == [100, 100, 100]


def test_identical_neighbours_become_one_frame_with_the_summed_delay() -> None:
    """Runs of identical frames merge into one frame lasting the whole run."""
    frames = [flat(RED), flat(RED), flat(RED), flat(BLUE), flat(RED), flat(RED)]
    data, stream = write(frames, 30.0)
    decoded, durations, _ = decode(data)
    assert stream.frames == 3
    assert [tuple(frame[0, 0]) for frame in decoded] == [RED, BLUE, RED]
    assert durations == [90, 30, 60]


def test_a_frame_that_is_changed_after_adding_is_written_as_it_was() -> None:
    """The stream keeps its own copy: a caller reusing its buffer does not alter or merge it."""
    handle = io.BytesIO()
    stream = GifStream(handle, 50.0)
    buffer = flat(RED)
    stream.add(buffer)
    buffer[:] = GREEN
    stream.add(buffer)
    stream.close()
    decoded, durations, _ = decode(handle.getvalue())
    assert [tuple(frame[0, 0]) for frame in decoded] == [RED, GREEN]
    assert durations == [50, 50]


@pytest.mark.parametrize(("delay_ms", "centiseconds"), [
    (1.0, 1), (4.0, 1), (16.0, 2), (24.0, 2), (26.0, 3), (1000.0, 100), (655350.0, 0xFFFF),
    (1e9, 0xFFFF)])
def test_delays_are_rounded_to_centiseconds_within_what_a_gif_can_hold(
        delay_ms: float, centiseconds: int) -> None:
    """A delay is written in whole centiseconds, at least 1 and at most 65535."""
    data, _ = write([flat(RED), flat(GREEN)], delay_ms)
    _, durations, _ = decode(data)
    assert durations == [centiseconds * 10] * 2
    control = b"\x21\xf9\x04\x04" + struct.pack("<H", centiseconds) + b"\x00\x00"
    assert data.count(control) == 2


def test_the_file_starts_with_a_gif89a_header_without_a_global_palette_and_loops() -> None:
    """Header, screen size, no global colour table, then the NETSCAPE loop-for-ever block."""
    data, _ = write([flat(RED, 3, 7)])
    assert data[:13] == b"GIF89a" + struct.pack("<HH", 7, 3) + b"\x70\x00\x00"
    assert data[13:32] == b"\x21\xff\x0bNETSCAPE2.0\x03\x01\x00\x00\x00"
    assert data[32:40] == b"\x21\xf9\x04\x04\x04\x00\x00\x00"  # no disposal, 4 cs, no transparency
    assert data[40:49] == b"\x2c" + struct.pack("<HHHH", 0, 0, 7, 3)
    with Image.open(io.BytesIO(data), formats=["GIF"]) as img:
        assert img.size == (7, 3)
        assert img.n_frames == 1


def test_each_frame_carries_its_own_colour_table() -> None:
    """Every image descriptor sits at the origin, covers the whole screen, has a local table."""
    data, _ = write([flat(RED, 2, 3), flat(BLUE, 2, 3)])
    descriptor = b"\x2c" + struct.pack("<HHHH", 0, 0, 3, 2)
    starts = [i for i in range(len(data)) if data.startswith(descriptor, i)]
    assert len(starts) == 2
    for start in starts:
        packed = data[start + 9]
        assert packed & 0x80  # local colour table present
        assert not packed & 0x40  # tiny frames are not interlaced


def test_frames_16_pixels_each_way_are_marked_interlaced() -> None:
    """Pillow interlaces such frames; the descriptor must say so or the rows come out shuffled."""
    data, _ = write([quadrants(16, 16)])
    descriptor = b"\x2c" + struct.pack("<HHHH", 0, 0, 16, 16)
    start = data.index(descriptor)
    assert data[start + 9] & 0xC0 == 0xC0


def test_a_frame_of_another_size_is_refused() -> None:
    """All frames share the first one's size; another size is a ValueError naming both."""
    handle = io.BytesIO()
    stream = GifStream(handle, 40.0)
    stream.add(flat(RED, 4, 5))
    with pytest.raises(ValueError, match=r"^a 3×4 frame in a 5×4 GIF$"):
        stream.add(flat(RED, 4, 3))
    with pytest.raises(ValueError, match=r"^a 5×2 frame in a 5×4 GIF$"):
        stream.add(flat(RED, 2, 5))
    stream.add(flat(GREEN, 4, 5))
    stream.close()
    decoded, _, _ = decode(handle.getvalue())
    assert [tuple(frame[0, 0]) for frame in decoded] == [RED, GREEN]


def test_a_stream_without_frames_writes_nothing() -> None:
    """Closing before any frame leaves the handle empty (no header, no trailer)."""
    data, stream = write([])
    assert data == b""
    assert stream.frames == 0
    assert stream.size is None


def test_frames_are_written_as_they_come() -> None:
    """Adding a different frame writes the previous one at once; the last waits for close."""
    handle = io.BytesIO()
    stream = GifStream(handle, 40.0)
    assert stream.delay_ms == 40.0
    assert stream.handle is handle
    stream.add(flat(RED))
    assert stream.size == (5, 4)
    assert stream.frames == 0
    header = len(handle.getvalue())
    assert header == 32
    stream.add(flat(RED))
    assert len(handle.getvalue()) == header and stream.frames == 0
    stream.add(flat(BLUE))
    assert stream.frames == 1
    assert len(handle.getvalue()) > header
    stream.close()
    assert stream.frames == 2


def test_more_than_255_colours_are_quantised_to_255_without_dithering() -> None:
    """Too many colours are reduced to at most 255, and equal input pixels stay equal (no
    dither noise between identical rows)."""
    rng = np.random.default_rng(7)
    row = rng.integers(0, 256, (1, 300, 3), dtype=np.uint8)
    frame = np.repeat(row, 6, axis=0)
    data, _ = write([frame])
    decoded, _, _ = decode(data)
    got = decoded[0]
    assert got.shape == (6, 300, 3)
    assert (got == got[:1]).all()
    assert 200 < len(np.unique(got.reshape(-1, 3), axis=0)) <= 255
    assert np.abs(got.astype(int) - frame).max() < 64


def test_a_frame_of_exactly_256_colours_is_reduced_to_255() -> None:
    """The palette holds 255 colours, even when 256 would fit the frame exactly."""
    frame = np.zeros((1, 256, 3), np.uint8)
    frame[0, :, 0] = np.arange(256)
    frame[0, :, 1] = 255 - np.arange(256)
    decoded, _, _ = decode(write([frame])[0])
    assert len(np.unique(decoded[0].reshape(-1, 3), axis=0)) <= 255


@pytest.mark.parametrize("count", [2, 3, 5, 6, 8, 9, 17, 33, 65, 129])
def test_frames_with_a_few_colours_keep_every_colour(count: int) -> None:
    """Colour tables of every size (2 to 256 entries) are declared with their right size."""
    rng = np.random.default_rng(count)
    colours = rng.choice(256, (count, 3)).astype(np.uint8)
    colours[:, 0] = np.arange(count) * (255 // count)  # all distinct
    frame = colours[np.arange(2 * count) % count][None]
    frames = [frame, frame[:, ::-1].copy()]
    decoded, _, _ = decode(write(frames)[0])
    for got, want in zip(decoded, frames, strict=True):
        assert np.array_equal(got, want)


def test_a_very_wide_frame_keeps_its_full_width() -> None:
    """Sizes up to the GIF limit of 65535 are written unsigned (a 40000-pixel strip)."""
    frame = flat(RED, 1, 40000)
    frame[0, 20000:] = BLUE
    data, _ = write([frame])
    assert data[6:10] == struct.pack("<HH", 40000, 1)
    decoded, _, _ = decode(data)
    assert np.array_equal(decoded[0], frame)


def _other_pillow(monkeypatch: pytest.MonkeyPatch, *, local_table: bool, extensions: bool,
                  image: bool = True) -> None:
    """Make Pillow's one-frame GIFs look as other Pillow versions may write them: extensions
    (a comment, a graphic control block) before the image, its palette as a local colour table
    (the screen descriptor then declaring a different table size without the global flag)."""
    original = Image.Image.save

    def save(self: Image.Image, fp: io.BytesIO, format: str | None = None, **params) -> None:
        buffer = io.BytesIO()
        original(self, buffer, format, **params)
        data = buffer.getvalue()
        packed = data[10]
        end = 13 + 3 * (2 << (packed & 0x07))
        table, rest = data[13:end], data[end:]
        assert rest[0] == 0x2C
        extra = (b"\x21\xfe\x02hi\x03abc\x00" + b"\x21\xf9\x04\x00\x00\x00\x00\x00"
                 if extensions else b"")
        if not image:
            fp.write(data[:end] + extra + b"\x3b")
        elif local_table:
            bits = packed & 0x07
            fp.write(data[:10] + bytes([0x70 | (bits - 1)]) + data[11:13] + extra + rest[:9]
                     + bytes([rest[9] | 0x80 | bits]) + table + rest[10:])
        else:
            fp.write(data[:end] + extra + rest)

    monkeypatch.setattr(Image.Image, "save", save)


@pytest.mark.parametrize(("local_table", "extensions"), [(False, True), (True, False),
                                                         (True, True)])
def test_other_layouts_of_pillows_one_frame_gif_give_the_same_frames(
        monkeypatch: pytest.MonkeyPatch, local_table: bool, extensions: bool) -> None:
    """Extensions before Pillow's image are skipped and a local colour table is taken."""
    frames = [quadrants(4, 6), flat(GREEN, 4, 6), quadrants(18, 16)[:4, :6].copy()]
    six = flat(RED, 4, 6)
    six[0] = [(i * 40, 255 - i * 40, 7) for i in range(6)]
    frames.append(six)
    _other_pillow(monkeypatch, local_table=local_table, extensions=extensions)
    data = write(frames)[0]
    monkeypatch.undo()
    decoded, durations, _ = decode(data)
    assert len(decoded) == 4 and durations == [40] * 4
    for got, want in zip(decoded, frames, strict=True):
        assert np.array_equal(got, want)


def test_a_pillow_gif_without_an_image_is_an_error(monkeypatch: pytest.MonkeyPatch) -> None:
    """Should Pillow write no image block, the stream says so rather than write garbage."""
    _other_pillow(monkeypatch, local_table=False, extensions=True, image=False)
    stream = GifStream(io.BytesIO(), 40.0)
    with pytest.raises(ValueError, match=r"^Pillow wrote a GIF without an image block$"):
        stream.add(flat(RED))
