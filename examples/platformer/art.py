"""The platformer's tile images, drawn by code: ``python -m examples.platformer.art`` writes them.

``images/``: ``ground.png`` and ``ground_top.png`` (a solid tile inside the ground and on its
surface), ``plank.png`` (a one-way platform's slab), the player (looking either way), the enemy,
the goal's and the checkpoints' flags, and ``slope_<kind>.png`` for each slope kind of
:mod:`framework.tiles` (ground under the slope, grass along its surface, transparent above);
``levels/tiles.png``: the tileset the ``.tmj`` maps name, so they open in Tiled with pictures,
three tiles a row in the order of ``levels.TILE_KINDS`` (solid, one-way, spikes, then the six
slopes and the step; the first row is the original three-tile tileset, so its tile ids keep their
meaning), and ``step.png``.
The game uses the images for 32-unit tiles and plain colours otherwise; runs without a renderer
never load them.
"""

from __future__ import annotations

import struct
import zlib
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from framework.tiles import HEIGHTS, SLOPES

__all__ = ["IMAGES", "TILE", "coin_sheet", "enemy", "enemy_sheet", "flag", "ground", "main", "plank", "player",
           "player_sheet", "slope", "spikes", "step", "tileset", "write_png"]

HERE = Path(__file__).parent
IMAGES = HERE / "images"
TILE = 32

GROUND = (70, 80, 108)
GROUND_DARK = (56, 64, 88)
GRASS = (104, 190, 92)
GRASS_DARK = (70, 150, 70)
GRASS_LIGHT = (150, 220, 130)  # the light line along the grass's top
PLANK = (184, 138, 84)
PLANK_DARK = (128, 90, 52)
SPIKE = (226, 70, 70)


def _noise(h: int, w: int, seed: int) -> NDArray[np.bool_]:
    """Deterministic speckle mask: about one pixel in nine."""
    y, x = np.mgrid[0:h, 0:w]
    v = (x * 374761393 + y * 668265263 + seed * 2246822519) & 0xFFFFFFFF
    v = ((v ^ (v >> 13)) * 1274126177) & 0xFFFFFFFF
    return (v % 9) == 0


def _fill(h: int, w: int, color: tuple[int, int, int]) -> NDArray[np.uint8]:
    img = np.zeros((h, w, 4), dtype=np.uint8)
    img[..., :3] = color
    img[..., 3] = 255
    return img


def ground(top: bool) -> NDArray[np.uint8]:
    img = _fill(TILE, TILE, GROUND)
    img[_noise(TILE, TILE, 1), :3] = GROUND_DARK
    img[-1, :, :3] = GROUND_DARK  # a faint seam between tiles
    img[:, -1, :3] = GROUND_DARK
    if top:
        x = np.arange(TILE)
        depth = 5 + ((x * 7) % 5 == 0) + ((x * 3) % 4 == 0)  # grass hanging 5-7 px down
        for col in range(TILE):
            img[: depth[col], col, :3] = GRASS
            img[depth[col] - 1, col, :3] = GRASS_DARK
        img[0, :, :3] = GRASS_LIGHT
    return img


def slope(kind: str) -> NDArray[np.uint8]:
    """A slope tile: ground below the surface line of ``kind`` (``framework.tiles.HEIGHTS``), grass
    5-7 px deep (across the slope) under it, transparent above."""
    left, right = HEIGHTS[kind]
    img = ground(False)
    y, x = np.mgrid[0:TILE, 0:TILE]
    rise = (right - left) * TILE  # surface height rises by this over the tile
    # Height of each pixel's centre above the tile's bottom, and of the surface above that column.
    above = TILE - (y + 0.5)
    surface = left * TILE + rise * (x + 0.5) / TILE
    below = surface - above  # > 0 under the surface
    img[below <= 0.0] = 0
    stretch = float(np.hypot(1.0, rise / TILE))  # vertical depth of grass of a given thickness
    depth = (5 + ((x * 7) % 5 == 0) + ((x * 3) % 4 == 0)) * stretch
    grass = (below > 0.0) & (below <= depth)
    img[grass, :3] = GRASS
    img[grass & (below > depth - 1.0 * stretch), :3] = GRASS_DARK
    img[(below > 0.0) & (below <= 1.0 * stretch), :3] = GRASS_LIGHT
    return img


def step() -> NDArray[np.uint8]:
    """A quarter-tile step: the ground tile's top quarter (grass included) on the cell's bottom
    quarter, transparent above."""
    img = np.zeros((TILE, TILE, 4), dtype=np.uint8)
    img[-TILE // 4:] = ground(True)[: TILE // 4]
    return img


def plank() -> NDArray[np.uint8]:
    img = _fill(8, TILE, PLANK)
    img[0, :, :3] = (214, 170, 112)
    img[-1, :, :3] = PLANK_DARK
    img[:, 0, :3] = img[:, -1, :3] = PLANK_DARK
    img[3:5, 3:5, :3] = img[3:5, -5:-3, :3] = PLANK_DARK  # nails
    return img


def spikes() -> NDArray[np.uint8]:
    img = np.zeros((TILE, TILE, 4), dtype=np.uint8)
    h = int(0.55 * TILE)
    for row in range(h):  # rows from the tip down (image rows are top first)
        half = 0.42 * TILE * (row + 1) / h
        y = TILE - h + row
        x0, x1 = int(round(TILE / 2 - half)), int(round(TILE / 2 + half))
        img[y, x0:x1, :3] = SPIKE
        img[y, x0:x1, 3] = 255
    return img


def _ellipse_mask(h: int, w: int, cy: float, cx: float, ry: float, rx: float) -> NDArray[np.bool_]:
    y, x = np.mgrid[0:h, 0:w]
    return ((y + 0.5 - cy) / ry) ** 2 + ((x + 0.5 - cx) / rx) ** 2 <= 1.0


def _outline(img: NDArray[np.uint8], color: tuple[int, int, int]) -> None:
    """Darken the opaque pixels that touch a transparent one (or the edge)."""
    a = img[..., 3] > 0
    pad = np.pad(a, 1)
    inner = pad[:-2, 1:-1] & pad[2:, 1:-1] & pad[1:-1, :-2] & pad[1:-1, 2:]
    img[a & ~inner, :3] = color


def player(facing: int) -> NDArray[np.uint8]:
    """24 x 28: a round-cornered blue fellow with eyes looking where he goes."""
    w, h = 24, 28
    img = np.zeros((h, w, 4), dtype=np.uint8)
    body = _ellipse_mask(h, w, 12, 12, 12.5, 12.5) | (np.mgrid[0:h, 0:w][0] >= 12)
    img[body, :3] = (84, 176, 255)
    img[body, 3] = 255
    img[22:, :, :3] = np.where(body[22:, :, None], (60, 130, 210), 0)
    _outline(img, (34, 84, 150))
    for ex in (7, 15):
        x = ex + (1 if facing > 0 else -1)
        img[8:14, x - 2:x + 2, :3] = 255
        px = x + (0 if facing > 0 else -2)
        img[9:13, px:px + 2, :3] = (20, 24, 40)
    return img


def enemy() -> NDArray[np.uint8]:
    """24 x 22: a grumpy purple dome on dark feet."""
    w, h = 24, 22
    img = np.zeros((h, w, 4), dtype=np.uint8)
    dome = _ellipse_mask(h, w, 12, 12, 12, 12.5) & (np.mgrid[0:h, 0:w][0] < 18)
    img[dome, :3] = (196, 84, 164)
    img[dome, 3] = 255
    img[18:22, 2:10, :3] = img[18:22, 14:22, :3] = (70, 30, 60)
    img[18:22, 2:10, 3] = img[18:22, 14:22, 3] = 255
    _outline(img, (120, 40, 100))
    for x in (6, 14):
        img[8:13, x:x + 4, :3] = 255
        img[10:13, x + 1:x + 3, :3] = (20, 24, 40)
    img[6, 5:10, :3] = img[6, 14:19, :3] = (70, 30, 60)  # brows
    img[7, 8:10, :3] = img[7, 14:16, :3] = (70, 30, 60)
    return img


def player_sheet() -> NDArray[np.uint8]:
    """7 frames of 24 x 28 in a row, facing right (the renderer mirrors them for left): idle (2:
    standing, then breathing in a pixel), run (4: the feet apart and together, bobbing), jump (1:
    feet tucked)."""
    base = player(1)
    frames = [base, np.roll(base, -1, axis=0)]
    for k in range(4):
        f = np.roll(base, -1 if k % 2 else 0, axis=0).copy()
        f[24:, :] = 0
        foot = (60, 130, 210, 255)
        apart = k in (0, 2)
        for x0 in ((2, 16) if apart else (6, 12)):
            f[24:28, x0:x0 + 6] = foot
        frames.append(f)
    jump = base.copy()
    jump[22:, :] = 0
    jump[22:25, 4:20] = (60, 130, 210, 255)
    frames.append(jump)
    return np.concatenate(frames, axis=1)


def enemy_sheet() -> NDArray[np.uint8]:
    """2 frames of 24 x 22 (walking: the feet step), facing left as :func:`enemy`."""
    a = enemy()
    b = a.copy()
    b[18:22] = 0
    b[18:22, 4:12, :3] = b[18:22, 12:20, :3] = (70, 30, 60)
    b[18:22, 4:12, 3] = b[18:22, 12:20, 3] = 255
    return np.concatenate([a, b], axis=1)


def coin_sheet() -> NDArray[np.uint8]:
    """4 frames of 16 x 16: a gold coin turning (full, narrower, edge-on, narrower)."""
    frames = []
    for rx in (7.5, 5.0, 1.5, 5.0):
        img = np.zeros((16, 16, 4), dtype=np.uint8)
        disc = _ellipse_mask(16, 16, 7.5, 7.5, 7.5, rx)
        img[disc] = (255, 212, 64, 255)
        _outline(img, (200, 150, 30))
        if rx > 2:
            img[4:12, 7:9, :3] = np.where(disc[4:12, 7:9, None], (255, 240, 150), img[4:12, 7:9, :3])
        frames.append(img)
    return np.concatenate(frames, axis=1)


def flag(width: int, color: tuple[int, int, int]) -> NDArray[np.uint8]:
    """``width`` x 32: a pole with a flag (the goal: 32 wide; a checkpoint: 16)."""
    img = np.zeros((32, width, 4), dtype=np.uint8)
    pole = 3 if width < 32 else 8
    img[2:32, pole:pole + 2] = (200, 200, 210, 255)
    img[1:3, pole - 1:pole + 3] = (240, 220, 120, 255)
    fw = width - pole - 3
    for row in range(3, 13):
        span = fw - abs(row - 7) * (fw // 10 if width < 32 else 1)
        img[row, pole + 2:pole + 2 + max(span, 2)] = (*color, 255)
    img[29:32, max(pole - 3, 0):pole + 5] = (120, 120, 130, 255)
    return img


def tileset() -> NDArray[np.uint8]:
    """96 wide, for Tiled: solid, one-way (a plank on the top quarter), spikes; then the slopes, in
    the order of ``framework.tiles.SLOPES``, then the quarter-tile step, three a row."""
    tiles = [ground(True), np.pad(plank(), ((0, TILE - 8), (0, 0), (0, 0))), spikes()]
    tiles += [slope(k) for k in SLOPES] + [step()]
    rows = -(-len(tiles) // 3)
    img = np.zeros((rows * TILE, 3 * TILE, 4), dtype=np.uint8)
    for i, tile in enumerate(tiles):
        r, c = divmod(i, 3)
        img[r * TILE:(r + 1) * TILE, c * TILE:(c + 1) * TILE] = tile
    return img


def write_png(path: Path, rgba: NDArray[np.uint8]) -> None:
    """``(h, w, 4)`` uint8, top row first, as an RGBA PNG (stdlib only)."""
    h, w = rgba.shape[:2]
    raw = np.concatenate([np.zeros((h, 1), dtype=np.uint8), rgba.reshape(h, w * 4)], axis=1).tobytes()

    def chunk(tag: bytes, data: bytes) -> bytes:
        crc = zlib.crc32(tag + data) & 0xFFFFFFFF
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", crc)

    path.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 6, 0, 0, 0))
                     + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def main() -> None:
    IMAGES.mkdir(exist_ok=True)
    write_png(IMAGES / "ground.png", ground(False))
    write_png(IMAGES / "ground_top.png", ground(True))
    write_png(IMAGES / "plank.png", plank())
    write_png(IMAGES / "player_right.png", player(1))
    write_png(IMAGES / "player_left.png", player(-1))
    write_png(IMAGES / "enemy.png", enemy())
    write_png(IMAGES / "player_sheet.png", player_sheet())
    write_png(IMAGES / "enemy_sheet.png", enemy_sheet())
    write_png(IMAGES / "coin_sheet.png", coin_sheet())
    write_png(IMAGES / "goal.png", flag(32, (90, 224, 120)))
    write_png(IMAGES / "checkpoint.png", flag(16, (150, 150, 150)))
    write_png(IMAGES / "checkpoint_on.png", flag(16, (120, 230, 255)))
    for kind in SLOPES:
        write_png(IMAGES / f"{kind}.png", slope(kind))
    write_png(IMAGES / "step.png", step())
    write_png(HERE / "levels" / "tiles.png", tileset())


if __name__ == "__main__":
    main()
