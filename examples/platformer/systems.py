"""The platformer's systems and collision handlers: plain ``fn(scene, dt)`` / ``fn(scene, event)``.

Where each runs in a step (see :func:`install`)::

    before movement   level_flow -> move_platforms -> swing_platforms -> control_player -> walk_enemies
    movement          (framework: integrate velocities, gravity; moving platforms move)
    character         (framework: the player and the walkers move and slide with their
                       CharacterController: slopes, steps, riding platforms, one-way platforms)
    before response   weigh_on_bridges
    ccd .. response   (framework: sweep, broad phase, contacts and events, push-out and slide; or
                       the soft step, with the bridges' joints)
    after response    stand_on_bridges -> sense_player -> sense_enemies -> fall_out -> animate ->
                      follow_camera
    end of step       collision handlers: coins, spikes, enemies, checkpoints, the goal

The game's own movement code is input -> the velocity wanted: the framework's character
controller does the rest and reports ``on_floor``, ``floor_entity`` and ``on_wall``. Everything
else collision-related comes from the pipeline: its events (``scene.on_collision``), its contacts
(``scene.contacts``) and its queries (``scene.query_point``).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from framework import Hitbox, Transform, Velocity
from framework.character import CharacterController
from framework.components import Visual
from framework.events import CollisionEvent
from framework.input import Input

from .animations import animations
from .components import (
    ONE_WAY,
    SOLID,
    BridgePlank,
    Checkpoint,
    Coin,
    Enemy,
    GameState,
    Goal,
    Hazard,
    MovingPlatform,
    Player,
    SwingingPlatform,
    SwingRope,
    Tuning,
)

if TYPE_CHECKING:
    from framework import Scene

__all__ = ["install", "kill_player"]

LEFT, RIGHT, JUMP, DOWN = ("left", "a"), ("right", "d"), ("space", "up", "w"), ("down", "s")
LEDGE_PROBE = 0.8  # tiles: a walker turns where the ground ahead drops further than this
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
        index = state.level_index + (1 if state.pending == "next" else 0)
        game.use_solver_of(index)  # (when this step ends: a solver changes only between steps)
    else:
        index = state.level_index + (1 if state.pending == "next" else 0)
        state.pending = None
        game.spawn_level(index)


def move_platforms(scene: Scene, dt: float) -> None:
    """Steer each moving platform toward its current end; wait there a moment, then turn back."""
    for _e, (plat, t, v) in scene.query(MovingPlatform, Transform, Velocity):
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


def swing_platforms(scene: Scene, dt: float) -> None:
    """Give each swinging platform the velocity (x, y and angular) that takes it from where it is
    to its exact pendulum pose at the end of this step (:meth:`.SwingingPlatform.pose` of its
    clock advanced by ``dt``): the path is the analytic one, no error adds up from step to step.
    Whoever stands on the board is carried by the motion of the board's point under its feet (its
    displacement and its turn: the character controller's riding). Ropes turn with their swings."""
    if dt <= 0.0:
        return
    for _e, (sw, t, v) in scene.query(SwingingPlatform, Transform, Velocity):
        sw.time += dt
        x, y, theta = sw.pose(sw.time)
        v.x, v.y, v.angular = (x - t.x) / dt, (y - t.y) / dt, (theta - t.rotation) / dt
    for _e, (rope, t, v) in scene.query(SwingRope, Transform, Velocity):
        v.x, v.y = (rope.swing.pivot[0] - t.x) / dt, (rope.swing.pivot[1] - t.y) / dt
        v.angular = (rope.swing.angle(rope.swing.time) - t.rotation) / dt


def weigh_on_bridges(scene: Scene, dt: float) -> None:
    """The player weighs on the bridge plank it stands on. The character controller moves the
    player as a kinematic body, which presses on nothing; so after it has moved (and before the
    soft step solves the bridge's hinges), the plank under its feet gets the impulse of the
    player's weight over the step, ``push_mass * gravity * dt``, at the point under the feet (its
    bottom middle): the bridge then carries the player as it would a weight of that mass hung
    there, and sags under it (as :func:`.bridge.hang` says, tested)."""
    planks = scene.query(BridgePlank)
    if not planks or dt <= 0.0:
        return
    tu: Tuning = scene.resources[Tuning]
    gx, gy = scene.gravity
    jx, jy = tu.push_mass * gx * dt, tu.push_mass * gy * dt
    for _e, (_p, t, hb, ctrl) in scene.query(Player, Transform, Hitbox, CharacterController):
        floor = ctrl.floor_entity
        if not ctrl.on_floor or floor is None or scene.try_get(floor, BridgePlank) is None:
            continue
        pt, pv, phb = scene.get(floor, Transform), scene.get(floor, Velocity), scene.get(floor, Hitbox)
        mass, (cx, cy), inertia = phb.mass_data
        c, s = math.cos(pt.rotation), math.sin(pt.rotation)
        rx = t.x - (pt.x + c * cx - s * cy)  # from the plank's centre of mass to the feet
        ry = t.y - hb.shape.height * 0.5 - (pt.y + s * cx + c * cy)
        pv.x += jx / mass
        pv.y += jy / mass
        pv.angular += (rx * jy - ry * jx) / inertia


def stand_on_bridges(scene: Scene, dt: float) -> None:
    """Keep the player standing on the bridge deck under it. The character controller stood it on
    a plank, then the soft step moved the planks on: their hinges and the player's weight changed
    their velocity from the one the controller rode by, so the deck may now be a little below the
    feet, or above them, in them (where two planks meet in them at once, pushed out of one into the
    other, the controller would find the player crushed). So here the player is moved straight up
    or down onto the deck: its feet, the bottom of its box, a hair (2**-20 tile) above the highest
    point of the planks' top faces under it. Not if that move would put it into anything (the
    ground at a bridge's end, a ceiling): then the controller sees to it next step as to any floor
    that moved."""
    planks = scene.query(BridgePlank)
    if not planks:
        return
    tile = _tile(scene)
    for _e, (_p, t, hb, ctrl) in scene.query(Player, Transform, Hitbox, CharacterController):
        floor = ctrl.floor_entity
        if not ctrl.on_floor or floor is None or scene.try_get(floor, BridgePlank) is None:
            continue
        w, h = hb.shape.width, hb.shape.height
        x0, x1, feet = t.x - 0.5 * w, t.x + 0.5 * w, t.y - 0.5 * h
        top = None
        for e, _plank in planks:
            # its top face, corner to corner; the highest of it over the feet is at an end of
            # the part of it over them (it is straight)
            pt, box = scene.get(e, Transform), scene.get(e, Hitbox).shape
            hl, ht = max(px for px, _py in box.points), max(py for _px, py in box.points)  # (a centred box)
            c, s = math.cos(pt.rotation), math.sin(pt.rotation)
            (ax, ay), (bx, by) = sorted((pt.x + c * dx - s * ht, pt.y + s * dx + c * ht) for dx in (-hl, hl))
            lo, hi = max(ax, x0), min(bx, x1)
            if lo > hi or bx == ax:
                continue
            for x in (lo, hi):
                y = ay + (by - ay) * (x - ax) / (bx - ax)
                top = y if top is None else max(top, y)
        if top is None:
            continue
        dy = top + 2.0**-20 * tile - feet
        if dy == 0.0 or scene.query_shape(hb.shape, (t.x, t.y + dy), mask=ctrl.solid_mask or hb.mask):
            continue
        t.y += dy


def control_player(scene: Scene, dt: float) -> None:
    """Input -> the velocity the player wants: run, jump (coyote time, buffering, variable
    height), drop through one-way platforms. The character controller moves the body."""
    tu: Tuning = scene.resources[Tuning]
    tile = _tile(scene)
    keys = scene.resources[Input]
    for _e, (p, t, v, hb, ctrl) in scene.query(Player, Transform, Velocity, Hitbox, CharacterController):
        p.prev_bottom = t.y - hb.shape.height * 0.5
        p.since_ground = 0.0 if p.grounded else p.since_ground + dt
        p.since_jump_press = 0.0 if keys.was_pressed(*JUMP) else p.since_jump_press + dt
        vx, vy = v.x, v.y

        # Drop through a one-way platform: down + jump while standing on one.
        on_one_way = p.grounded and p.ground is not None and scene.exists(p.ground) and \
            scene.get(p.ground, Hitbox).one_way
        if keys.is_held(*DOWN) and p.since_jump_press == 0.0 and on_one_way:
            ctrl.drop_through = True
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
        if vx != v.x:
            v.x = vx
        if vy != v.y:
            v.y = vy


def walk_enemies(scene: Scene, dt: float) -> None:
    for _e, (en, t, v, hb) in scene.query(Enemy, Transform, Velocity, Hitbox):
        en.prev_top = t.y + hb.shape.height * 0.5
        v.x = en.direction * en.speed


# --- after response -----------------------------------------------------------------------------


def sense_player(scene: Scene, dt: float) -> None:
    """Grounded: the character controller stood the player on a floor this step (tiles, slopes,
    one-way and moving platforms, crates); ``ground`` is what it stands on. A player crushed (a
    platform carried it into a ceiling) dies."""
    for e, (p, ctrl) in scene.query(Player, CharacterController):
        if ctrl.crushed:
            kill_player(scene, e)
            continue
        p.grounded = ctrl.on_floor
        p.ground = ctrl.floor_entity if ctrl.on_floor else None


def sense_enemies(scene: Scene, dt: float) -> None:
    """Walkers turn where their controller met a wall (or another walker) ahead, where they touch
    spikes ahead (the pipeline's contacts with the sensor), and before a ledge: a ray down from
    just past their front foot finds no ground within LEDGE_PROBE tiles (deep enough for the
    ground under the front foot on a 45-degree slope, 0.75 tiles; moving and swinging platforms do
    not count, walkers keep off them)."""
    tile = _tile(scene)
    for e, (en, t, hb, ctrl) in scene.query(Enemy, Transform, Hitbox, CharacterController):
        turn = ctrl.on_wall and ctrl.wall_normal[0] * en.direction < 0.0
        for other in _touching(scene, e):
            if scene.try_get(other, Hazard) is not None and (scene.get(other, Transform).x - t.x) * en.direction > 0:
                turn = True  # spikes ahead
        if ctrl.on_floor and not turn:
            front = t.x + en.direction * (hb.shape.width * 0.5 + 0.02 * tile)
            feet = t.y - hb.shape.height * 0.5
            hits = scene.raycast_all((front, feet + 0.05 * tile), (0.0, -1.0), (LEDGE_PROBE + 0.05) * tile,
                                     mask=SOLID | ONE_WAY)
            if not any(scene.try_get(h.entity, MovingPlatform) is None
                       and scene.try_get(h.entity, SwingingPlatform) is None for h in hits):
                turn = True  # a ledge ahead
        if turn and en.turned_frame != scene.frame:
            en.direction = -en.direction
            en.turned_frame = scene.frame


def _touching(scene: Scene, entity: int) -> list[int]:
    """The entities ``entity`` overlaps this step (the pipeline's contacts)."""
    c = scene.contacts
    rows = np.flatnonzero((c.a == entity) | (c.b == entity))
    return [int(c.b[i]) if int(c.a[i]) == entity else int(c.a[i]) for i in rows.tolist()]


def fall_out(scene: Scene, dt: float) -> None:
    """Falling below the level kills the player, and removes an enemy."""
    floor = _state(scene).bounds[1] - 2.0 * _tile(scene)
    for e, (_p, t) in scene.query(Player, Transform):
        if t.y < floor:
            kill_player(scene, e)
    for e, (_en, t) in scene.query(Enemy, Transform):
        if t.y < floor and scene.exists(e):
            scene.despawn(e)


def animate(scene: Scene, dt: float) -> None:
    """The player's animation follows its state (jumping or falling, running, standing) and looks
    the way it last ran; walkers look the way they walk (levels drawn with images only). Playing
    the animation already shown, or setting the flip it has, changes nothing."""
    if not _state(scene).art:
        return
    anims = animations()
    for e, (p, vis) in scene.query(Player, Visual):
        if vis.animation is None:
            continue
        v = scene.try_get(e, Velocity)
        running = v is not None and abs(v.x) > 1.0
        vis.play(anims["run" if running else "idle"] if p.grounded else anims["jump"], scene.time)
        if vis.flip_x != (p.facing < 0):
            vis.flip_x = p.facing < 0
    for _e, (en, vis) in scene.query(Enemy, Visual):
        if vis.animation is not None and vis.flip_x != (en.direction > 0):
            vis.flip_x = en.direction > 0


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
    ctrl = scene.get(player, CharacterController)
    ctrl.on_floor, ctrl.floor_entity, ctrl.drop_through = False, None, False
    ctrl.dropping.clear()
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

    for system in (level_flow, move_platforms, swing_platforms, control_player, walk_enemies):
        scene.add_system(system, before="movement")
    scene.add_system(weigh_on_bridges, before="response")
    for system in (stand_on_bridges, sense_player, sense_enemies, fall_out, animate, follow_camera):
        scene.add_system(system, after="response")
    scene.on_collision(P, Coin, on_coin)
    scene.on_collision(P, Hazard, on_hazard, kinds=("started", "ongoing"))
    scene.on_collision(P, Enemy, on_enemy, kinds=("started", "ongoing"))
    scene.on_collision(P, Checkpoint, on_checkpoint)
    scene.on_collision(P, Goal, on_goal)
