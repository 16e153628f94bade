"""Determinism: the same recorded input gives bit-identical state and events, run after run,
whatever ``PYTHONHASHSEED`` is and whatever fresh memory holds.

A small game (a player driven by a replay, random bodies from the replay's seed, coins a handler
despawns, bullets with continuous detection spawned by a system, a one-way platform, layers,
sleeping) is stepped in a fresh interpreter; each step's store columns and event reprs are hashed.
Two interpreters with different hash seeds must print the same digests, step for step.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

GAME = textwrap.dedent('''
    import hashlib, os, sys
    import numpy as np
    from framework import AABB, Circle, Hitbox, Polygon, Scene, Transform, Velocity
    from framework.input import Input
    from framework.replay import Replay

    class Coin: pass
    class Player: pass
    class Bullet: pass

    def game(replay):
        rng = np.random.default_rng(replay.seed)
        s = Scene(gravity=(0.0, -10.0), substeps=2, solver=os.environ.get("GAME_SOLVER", "exact"))
        for i in range(30):
            s.spawn(Transform(float(i), 0.0), Hitbox(AABB(1.0, 1.0), body="static"))
        s.spawn(Transform(-0.5, 4.0), Hitbox(AABB(1.0, 8.0), body="static"))
        s.spawn(Transform(29.5, 4.0), Hitbox(AABB(1.0, 8.0), body="static"))
        s.spawn(Transform(10.0, 2.5), Hitbox(AABB(4.0, 0.25), body="static", one_way=True))
        player = s.spawn(Transform(2.0, 1.0), Velocity(), Hitbox(AABB(0.8, 1.0), layer=2), Player())
        for _ in range(20):
            kind = int(rng.integers(3))
            shape = [AABB(0.5, 0.4), Circle(0.3), Polygon([(0, 0), (0.6, 0), (0.2, 0.5)])][kind]
            s.spawn(Transform(float(rng.uniform(1, 28)), float(rng.uniform(1, 7)), float(rng.uniform(0, 6))),
                    Velocity(float(rng.uniform(-3, 3)), 0.0),
                    Hitbox(shape, restitution=float(rng.uniform(0, 1)), mass=float(rng.uniform(0.5, 2))))
        for i in range(8):
            s.spawn(Transform(3.0 + 3 * i, 1.5), Hitbox(Circle(0.25), body="static", sensor=True, layer=4), Coin())
        s.on_collision(Player, Coin, lambda scene, ev: scene.despawn(ev.b))
        s.on_collision(Bullet, Hitbox, lambda scene, ev: scene.exists(ev.a) and scene.despawn(ev.a))

        def control(scene, dt):
            keys, v = scene.resources[Input], scene.get(player, Velocity)
            v.x = 5.0 * (keys.is_held("right") - keys.is_held("left"))
            if keys.was_pressed("up"):
                v.y = 7.0
            if keys.was_pressed("space"):
                t = scene.get(player, Transform)
                scene.spawn(Transform(t.x + 0.6, t.y), Velocity(60.0, 0.0), Hitbox(Circle(0.1), ccd=True), Bullet())

        s.add_system(control, before="movement")
        digest = hashlib.sha256()
        kinds = {"started": 0, "ongoing": 0, "ended": 0}
        for i in range(len(replay)):
            replay.apply(s, i)
            s.step(replay.dt)
            for name in sorted(s.store.cols):
                digest.update(s.store.cols[name][: s.store.n].tobytes())
            digest.update(repr(s.events).encode())
            for ev in s.events:
                kinds[ev.kind] += 1
            digest.update(repr(s.entities).encode())
            if i % 50 == 49:
                print(i + 1, digest.hexdigest())
        print("asleep", int(s.store.asleep.sum()), "entities", len(s.entities), "events", kinds)
        s.close()

    pattern = [["right"]] * 40 + [["right", "up"]] * 2 + [["right", "space"]] * 3 + [[]] * 20 + [["left"]] * 30
    pattern += [["left", "space"], ["left"], ["up"]] * 5 + [[]] * 40
    game(Replay.load(sys.argv[1]) if len(sys.argv) > 1 else Replay(pattern, dt=1 / 60, seed=2024))
''')


def run_game(tmp_path: Path, hash_seed: str, replay_file: Path | None = None, **env_vars: str) -> str:
    script = tmp_path / "game.py"
    script.write_text(GAME)
    env = dict(os.environ, PYTHONHASHSEED=hash_seed, **env_vars)
    args = [sys.executable, str(script)] + ([str(replay_file)] if replay_file else [])
    root = Path(__file__).resolve().parents[1]
    out = subprocess.run(args, capture_output=True, text=True, env=env, cwd=root, timeout=120)
    assert out.returncode == 0, out.stderr
    return out.stdout


@pytest.mark.slow
def test_same_replay_same_bytes_across_hash_seeds(tmp_path):
    a = run_game(tmp_path, "0")
    b = run_game(tmp_path, "12345")
    assert a.count("\n") == 4  # three digests (every 50 steps of 150) and a summary
    assert a == b
    summary = a.splitlines()[-1]
    assert "'started': 0" not in summary and "'ended': 0" not in summary, summary


@pytest.mark.slow
def test_replay_file_reproduces_the_recorded_run(tmp_path):
    from framework.replay import Replay

    pattern = [["right"]] * 40 + [["right", "up"]] * 2 + [["right", "space"]] * 3 + [[]] * 20 + [["left"]] * 30
    pattern += [["left", "space"], ["left"], ["up"]] * 5 + [[]] * 40
    path = tmp_path / "session.replay"
    Replay(pattern, dt=1 / 60, seed=2024).save(path)
    assert run_game(tmp_path, "777", path) == run_game(tmp_path, "0")


@pytest.mark.slow
@pytest.mark.parametrize("solver", ["exact", "soft"])
def test_same_bytes_whatever_fresh_memory_holds(tmp_path, solver):
    """A kernel that read memory it had not written (an ``np.empty`` slot) would step by whatever
    that memory held. glibc's ``MALLOC_PERTURB_`` fills memory as it is handed out and freed (the
    compiled kernels' arrays come from malloc): three fillings, one run each, the same digests."""
    runs = [run_game(tmp_path, "0", GAME_SOLVER=solver, **({"MALLOC_PERTURB_": fill} if fill else {}))
            for fill in ("", "85", "170")]
    assert runs[0].count("\n") == 4
    assert runs[1] == runs[0] and runs[2] == runs[0]
