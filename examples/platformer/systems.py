"""The platformer's systems and collision handlers: plain ``fn(scene, dt)`` / ``fn(scene, event)``.

Where each runs in a step (see :func:`install`)::

    before movement   level_flow -> move_platforms -> control_player -> walk_enemies
    movement          (framework: integrate velocities, gravity)
    after movement    carry_riders      the moving platform's displacement to whoever stands on it
    ccd .. response   (framework: sweep, broad phase, contacts and events, push-out and slide)
    after response    sense_player -> sense_enemies -> fall_out -> face -> follow_camera
    end of step       collision handlers: coins, spikes, enemies, checkpoints, the goal

Everything collision-related comes from the pipeline: the contacts it found this step
(``scene.contacts``), its events (``scene.on_collision``), its queries (``scene.query_point``) and
``framework.collide`` to check a reported contact after the response.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from framework import AABB, Hitbox, Transform, Velocity, collide
from framework.components import Visual
from framework.events import CollisionEvent
from framework.input import Input

from .components import (
    ONE_WAY,
    SOLID,
    Checkpoint,
    Coin,
    Enemy,
    GameState,
    Goal,
    Hazard,
    MovingPlatform,
    Player,
    Tuning,
)

if TYPE_CHECKING:
    from framework import Scene

__all__ = ["install", "kill_player"]

LEFT, RIGHT, JUMP, DOWN = ("left", "a"), ("right", "d"), ("space", "up", "w"), ("down", "s")
GROUND_NORMAL = 0.7  # a contact whose normal (toward the body) has y above this is ground
CHECKPOINT_ON = (120, 230, 255)


def _state(scene: Scene) -> GameState:
    return scene.resources[GameState]


def _tile(scene: Scene) -> float:
    return scene.resources[GameState].tile


# --- before movement ----------------------------------------------------------------------------


def level_flow(scene: Scene, dt: float) -> None:
    """R restarts the level; level changes (F1 and Esc are the window runner's).

    A level change takes two steps: this step despawns the old level (despawns wait for the end
    of the step), the next one spawns the new level before anything moves."""
    from .game import Game  # the Game object is a scene resource

    state, keys = _state(scene), scene.resources[Input]
    game: Game = scene.resources[Game]
    if keys.was_pressed("r") and state.pending is None:
        state.pending, state.pending_stage = "restart", 0
    if state.level_done and state.goal_timer > 0.0:
        state.goal_timer -= dt
        if state.goal_timer <= 0.0 and state.pending is None:
            if state.level_index + 1 < len(game.levels):
                state.pending, state.pending_stage = "next", 0
            else:
                state.finished = True
    if state.pending is None:
        return
    if state.pending_stage == 0:
        game.clear_level()
        state.pending_stage = 1
    else:
        index = state.level_index + (1 if state.pending == "next" else 0)
        state.pending = None
        game.spawn_level(index)


def move_platforms(scene: Scene, dt: float) -> None:
    """Steer each moving platform toward its current end; wait there a moment, then turn back."""
    for _e, (plat, t, v) in scene.query(MovingPlatform, Transform, Velocity):
        plat.start_pos = (t.x, t.y)  # carry_riders and sense_player take the difference
        if plat.waiting > 0.0:
            plat.waiting -= dt
            v.x = v.y = 0.0
            continue
        tx, ty = plat.end if plat.toward_end else plat.start
        dx, dy = tx - t.x, ty - t.y
        dist = (dx * dx + dy * dy) ** 0.5
        if dist <= plat.speed * dt:
            v.x, v.y = dx / dt, dy / dt  # arrive exactly this step, then wait and head back
            plat.toward_end = not plat.toward_end
            plat.waiting = plat.pause
        else:
            v.x, v.y = dx / dist * plat.speed, dy / dist * plat.speed


def control_player(scene: Scene, dt: float) -> None:
    """Run, jump (coyote time, buffering, variable height), drop through one-way platforms."""
    tu: Tuning = scene.resources[Tuning]
    tile = _tile(scene)
    keys = scene.resources[Input]
    for _e, (p, t, v, hb) in scene.query(Player, Transform, Velocity, Hitbox):
        p.prev_bottom = t.y - hb.shape.height * 0.5
        p.since_ground = 0.0 if p.grounded else p.since_ground + dt
        p.since_jump_press = 0.0 if keys.was_pressed(*JUMP) else p.since_jump_press + dt
        vx, vy = v.x, v.y

        # Drop through a one-way platform: down + jump while standing on one.
        if p.drop_timer > 0.0:
            p.drop_timer -= dt
            if p.drop_timer <= 0.0:
                hb.mask |= ONE_WAY
        on_one_way = p.grounded and p.ground is not None and scene.exists(p.ground) and \
            scene.get(p.ground, Hitbox).one_way
        if keys.is_held(*DOWN) and p.since_jump_press == 0.0 and on_one_way:
            hb.mask &= ~ONE_WAY
            p.drop_timer = tu.drop_time
            p.since_jump_press = 1e9
            p.grounded, p.ground, p.since_ground = False, None, 1e9

        # Jump: a press remembered for jump_buffer, from the ground or up to coyote_time after it.
        if p.since_jump_press <= tu.jump_buffer and p.since_ground <= tu.coyote_time:
            vy = tu.jump_speed * tile
            p.jumping = True
            p.since_jump_press = p.since_ground = 1e9
            p.grounded, p.ground = False, None
        if p.jumping and (vy <= 0.0 or not keys.is_held(*JUMP)):
            if vy > 0.0:
                vy *= tu.jump_cut  # released early: a lower jump
            p.jumping = False

        # Run: accelerate toward the target speed (quicker on the ground).
        want = (keys.is_held(*RIGHT) - keys.is_held(*LEFT)) * tu.run_speed * tile
        accel = (tu.ground_accel if p.grounded else tu.air_accel) * tile * dt
        vx = min(want, vx + accel) if want > vx else max(want, vx - accel)
        if want:
            p.facing = 1 if want > 0 else -1
        vy = max(vy, -tu.fall_speed * tile)
        p.vy_start = vy
        if vx != v.x:
            v.x = vx
        if vy != v.y:
            v.y = vy


def walk_enemies(scene: Scene, dt: float) -> None:
    for _e, (en, t, v, hb) in scene.query(Enemy, Transform, Velocity, Hitbox):
        en.prev_top = t.y + hb.shape.height * 0.5
        v.x = en.direction * en.speed


# --- after movement -----------------------------------------------------------------------------


def carry_riders(scene: Scene, dt: float) -> None:
    """Move whoever stood on a moving platform last step by the platform's displacement."""
    for _e, (p, t) in scene.query(Player, Transform):
        if p.ground is None or not scene.exists(p.ground):
            continue
        plat = scene.try_get(p.ground, MovingPlatform)
        if plat is None:
            continue
        pt = scene.get(p.ground, Transform)
        x0, y0 = plat.start_pos
        t.x += pt.x - x0
        t.y += pt.y - y0


# --- after response -----------------------------------------------------------------------------


def _touching(scene: Scene, entity: int) -> list[tuple[int, float, float, float]]:
    """This step's contacts of ``entity``: (other, normal x, normal y toward ``entity``, depth)."""
    c = scene.contacts
    out = []
    for i in np.flatnonzero((c.a == entity) | (c.b == entity)).tolist():
        a, b = int(c.a[i]), int(c.b[i])
        sign = -1.0 if a == entity else 1.0  # contact normals point from a to b
        out.append((b if a == entity else a, sign * float(c.nx[i]), sign * float(c.ny[i]), float(c.depth[i])))
    return out


def _on_top_of(t: Transform, hb: Hitbox, other_t: Transform, other_hb: Hitbox) -> bool:
    """Whether ``other`` is right under the feet: it overlaps a thin box just below the body, a
    hair narrower than the body (``framework.collide``, after the response has pushed the body out).

    The pipeline's raw contacts alone are not enough: a body pushed against a wall of tiles also
    overlaps, by a sliver, the top of the tile below the one it hits, a contact with an upward
    normal that the response then discards (it resolves the deepest contact first and measures
    the others again); taken as ground, it would let the player jump off walls."""
    w, h = hb.shape.width, hb.shape.height
    x, bottom = t.x + hb.offset[0], t.y + hb.offset[1] - h * 0.5
    depth = 0.05 * h
    feet = AABB(w * (1.0 - 2e-3), depth)
    ox, oy = other_hb.offset
    pose = (other_t.x + ox, other_t.y + oy, other_t.rotation)  # tiles and platforms: offsets never turn
    return collide(feet, (x, bottom - depth * 0.5), other_hb.shape, pose) is not None


def sense_player(scene: Scene, dt: float) -> None:
    """Grounded: one of this step's contacts (``scene.contacts``) is below the player, with an
    upward normal, and still right under the feet after the response.

    A one-way platform counts only if the feet were on or above its top when the step began (the
    pipeline's own landing rule), so rising through one or standing inside it is not standing on
    it; nothing counts while moving up, away from it. On a moving platform the player's vertical
    velocity is kept relative to it (zero while standing): carry_riders moves the player with it."""
    tol = 1e-3 * _tile(scene)
    for e, (p, t, v, hb) in scene.query(Player, Transform, Velocity, Hitbox):
        ground, best = None, -1
        for other, _nx, ny, _depth in _touching(scene, e):
            if ny < GROUND_NORMAL:
                continue
            ohb = scene.try_get(other, Hitbox)
            if ohb is None or ohb.sensor or scene.try_get(other, Enemy) is not None:
                continue
            plat = scene.try_get(other, MovingPlatform)
            ov = scene.try_get(other, Velocity)
            # A rider's velocity is relative to its platform; anyone else's is absolute.
            rel = p.vy_start if other == p.ground or ov is None else v.y - ov.y
            if rel > 1e-9:
                continue
            ot = scene.get(other, Transform)
            if ohb.one_way:
                y0 = plat.start_pos[1] if plat is not None else ot.y
                top = y0 + ohb.offset[1] + ohb.shape.height * 0.5
                if p.prev_bottom < top - tol:
                    continue
            if not _on_top_of(t, hb, ot, ohb):
                continue
            rank = 1 if plat is not None else 0  # on a platform and a tile at once: ride
            if rank > best:
                ground, best = other, rank
        p.grounded = ground is not None
        p.ground = ground
        if ground is not None and scene.try_get(ground, MovingPlatform) is not None:
            v.y = 0.0


def sense_enemies(scene: Scene, dt: float) -> None:
    """Walkers turn where the response stopped them (a wall, another enemy), where they touch
    spikes ahead (the pipeline's contacts with the sensor), and before a ledge
    (``scene.query_point`` just ahead of and below their feet finds no ground; moving platforms
    do not count, walkers keep off them)."""
    tile = _tile(scene)
    for e, (en, t, v, hb) in scene.query(Enemy, Transform, Velocity, Hitbox):
        turn = abs(v.x) < 0.5 * en.speed  # the response took away its walking speed
        grounded = False
        for other, _nx, ny, _depth in _touching(scene, e):
            if scene.try_get(other, Hazard) is not None:
                if (scene.get(other, Transform).x - t.x) * en.direction > 0:
                    turn = True  # spikes ahead
            elif ny >= GROUND_NORMAL and not scene.get(other, Hitbox).sensor:
                grounded = True
        if grounded and not turn:
            front = t.x + en.direction * (hb.shape.width * 0.5 + 0.1 * tile)
            below = t.y - hb.shape.height * 0.5 - 0.1 * tile
            # Walkers keep off moving platforms, so the ground ahead is static and changes only
            # where the probe enters another tile: the query is asked again only then.
            cell = (math.floor(front / tile), math.floor(below / tile))
            if cell != en.probe_cell:
                en.probe_cell = cell
                en.probe_ground = any(scene.try_get(o, MovingPlatform) is None
                                      for o in scene.query_point(front, below, mask=SOLID | ONE_WAY))
            if not en.probe_ground:
                turn = True  # a ledge ahead
        if turn and en.turned_frame != scene.frame:
            en.direction = -en.direction
            en.turned_frame = scene.frame


def fall_out(scene: Scene, dt: float) -> None:
    """Falling below the level kills the player, and removes an enemy."""
    floor = _state(scene).bounds[1] - 2.0 * _tile(scene)
    for e, (_p, t) in scene.query(Player, Transform):
        if t.y < floor:
            kill_player(scene, e)
    for e, (_en, t) in scene.query(Enemy, Transform):
        if t.y < floor and scene.exists(e):
            scene.despawn(e)


def face(scene: Scene, dt: float) -> None:
    """The player's picture looks the way it last ran (levels drawn with images only)."""
    if not _state(scene).art:
        return
    for _e, (p, vis) in scene.query(Player, Visual):
        want = "player_right.png" if p.facing > 0 else "player_left.png"
        if vis.image is not None and not vis.image.endswith(want):
            vis.image = vis.image.replace("player_left.png" if p.facing > 0 else "player_right.png", want)


def follow_camera(scene: Scene, dt: float) -> None:
    """Keep the player in view, the view inside the level (centred where the level is smaller)."""
    state = _state(scene)
    if state.player is None or not scene.exists(state.player):
        return
    t = scene.get(state.player, Transform)
    minx, miny, maxx, maxy = state.bounds
    vw, vh = state.view

    def clamp(c: float, lo: float, hi: float, span: float) -> float:
        if hi - lo <= span:
            return (lo + hi) * 0.5
        return min(max(c, lo + span * 0.5), hi - span * 0.5)

    state.camera = (clamp(t.x, minx, maxx, vw), clamp(t.y, miny, maxy, vh))


# --- collision handlers -------------------------------------------------------------------------


def kill_player(scene: Scene, player: int) -> None:
    """Count a death and put the player back at the last checkpoint, at rest."""
    p = scene.get(player, Player)
    if p.dead_frame == scene.frame:
        return
    state = _state(scene)
    state.deaths += 1
    hb = scene.get(player, Hitbox)
    t, v = scene.get(player, Transform), scene.get(player, Velocity)
    x, feet = state.checkpoint
    t.x, t.y = x, feet + hb.shape.height * 0.5
    v.x = v.y = 0.0
    hb.mask |= ONE_WAY
    fresh = Player(dead_frame=scene.frame, facing=p.facing)
    for name in fresh.__dataclass_fields__:
        setattr(p, name, getattr(fresh, name))
    p.prev_bottom = feet


def on_coin(scene: Scene, ev: CollisionEvent) -> None:
    if not scene.exists(ev.b):
        return  # already taken this step
    state = _state(scene)
    value = scene.get(ev.b, Coin).value
    state.coins += value
    state.coins_in_level += value
    scene.despawn(ev.b)


def on_hazard(scene: Scene, ev: CollisionEvent) -> None:
    kill_player(scene, ev.a)


def on_enemy(scene: Scene, ev: CollisionEvent) -> None:
    """Stomp (the player's feet were above the enemy's head when the step began) or die."""
    player, enemy = ev.a, ev.b
    if not (scene.exists(player) and scene.exists(enemy)):
        return
    p, en = scene.get(player, Player), scene.get(enemy, Enemy)
    if p.dead_frame == scene.frame:
        return
    tu: Tuning = scene.resources[Tuning]
    tile = _tile(scene)
    if p.prev_bottom >= en.prev_top - 0.2 * tile:
        scene.despawn(enemy)
        held = scene.resources[Input].is_held(*JUMP)
        scene.get(player, Velocity).y = (tu.jump_speed if held else tu.stomp_bounce) * tile
        p.jumping = held
        p.grounded, p.ground = False, None
        _state(scene).stomps += 1
    else:
        kill_player(scene, player)


def on_checkpoint(scene: Scene, ev: CollisionEvent) -> None:
    cp = scene.get(ev.b, Checkpoint)
    if cp.active:
        return
    for _e, other in scene.query(Checkpoint):
        other.active = False
    cp.active = True
    t, hb = scene.get(ev.b, Transform), scene.get(ev.b, Hitbox)
    _state(scene).checkpoint = (t.x, t.y - hb.shape.height * 0.5)
    for _e, (c, vis) in scene.query(Checkpoint, Visual):
        if vis.image is not None:
            vis.image = vis.image.replace("checkpoint_on.png", "checkpoint.png")
            if c.active:
                vis.image = vis.image.replace("checkpoint.png", "checkpoint_on.png")
        else:
            vis.color = (*CHECKPOINT_ON, 255) if c.active else (150, 150, 150, 255)


def on_goal(scene: Scene, ev: CollisionEvent) -> None:
    state = _state(scene)
    if state.level_done or state.pending is not None:
        return
    state.level_done = state.reached_goal = True
    state.levels_completed += 1
    state.goal_timer = 1.0  # a moment to see it, then the next level


def install(scene: Scene) -> None:
    """Add the game's systems and handlers to ``scene`` (once)."""
    from .components import Player as P

    for system in (level_flow, move_platforms, control_player, walk_enemies):
        scene.add_system(system, before="movement")
    scene.add_system(carry_riders, after="movement")
    for system in (sense_player, sense_enemies, fall_out, face, follow_camera):
        scene.add_system(system, after="response")
    scene.on_collision(P, Coin, on_coin)
    scene.on_collision(P, Hazard, on_hazard, kinds=("started", "ongoing"))
    scene.on_collision(P, Enemy, on_enemy, kinds=("started", "ongoing"))
    scene.on_collision(P, Checkpoint, on_checkpoint)
    scene.on_collision(P, Goal, on_goal)
