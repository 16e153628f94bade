"""Hash the state of reference scenes step by step: the proof that a change is bit-identical.

``python scripts/state_hash.py [--quick]`` prints one SHA-256 per scene: every step's positions,
rotations and velocities (by entity) and its collision events, fed into the hash in order. Run it
before and after a restructuring; equal hashes mean the pipeline computed the same bits.
"""

from __future__ import annotations

import argparse
import hashlib
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))


def _feed(h, scene) -> None:
    from framework import Transform, Velocity

    rows = []
    for e in scene.entities:
        t = scene.try_get(e, Transform)
        if t is None:
            continue
        v = scene.try_get(e, Velocity)
        rows.append((e, t.x, t.y, t.rotation, *((v.x, v.y, v.angular) if v is not None else (0.0, 0.0, 0.0))))
    h.update(np.array(rows, dtype=np.float64).tobytes())
    for ev in scene.events:
        h.update(repr(tuple(ev)).encode())


def run(scene, steps: int, dt: float) -> str:
    h = hashlib.sha256()
    for _ in range(steps):
        scene.step(dt)
        _feed(h, scene)
    return h.hexdigest()[:16]


def soak(bodies: int, steps: int, seed: int = 1, restitution: bool = True, rotation: bool = True) -> str:
    from test_soak import DT, build_level

    from framework.effects import DEFAULT_EFFECTS

    effects = None if rotation else DEFAULT_EFFECTS - {"rotation"}
    scene, _ents, _ = build_level(bodies, seed, restitution, effects)
    return run(scene, steps, DT)


def perf(n: int, steps: int, tiles: int = 0) -> str:
    from framework.bench import perf as p

    wl = p.make_boxes(n)
    if tiles:
        wl = p.with_tiles(wl, tiles, overlapping=True)
    return run(p.build_scene(wl), steps, p.DT)


def platformer(frames: int) -> str:
    """The platformer's scripted play through both shipped levels."""
    from examples.platformer.demo import Autoplay, play_all
    from examples.platformer.game import Game

    game = Game(autoplay=Autoplay(play_all))
    h = hashlib.sha256()
    for _ in range(frames):
        game.step()
        _feed(h, game.scene)
    game.close()
    return h.hexdigest()[:16]


SCENES = {
    "soak-200x1500": lambda q: soak(200, 300 if q else 1500),
    "soak-40x3000": lambda q: soak(40, 600 if q else 3000),
    "soak-40-inelastic-x1500": lambda q: soak(40, 300 if q else 1500, seed=2, restitution=False),
    # (polygons that do not turn: the translational solver alone, as before boxes could tip)
    "soak-200x1500-no-rotation": lambda q: soak(200, 300 if q else 1500, rotation=False),
    "perf-1k-x100": lambda q: perf(1000, 30 if q else 100),
    "perf-10k-x20": lambda q: perf(10_000, 5 if q else 20),
    "perf-1k-tiles-x50": lambda q: perf(1000, 20 if q else 50, tiles=20_000),
    "platformer-x3000": lambda q: platformer(600 if q else 3000),
}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--only", default="")
    args = ap.parse_args()
    for name, fn in SCENES.items():
        if args.only and args.only not in name:
            continue
        print(f"{name:28s} {fn(args.quick)}", flush=True)


if __name__ == "__main__":
    main()
