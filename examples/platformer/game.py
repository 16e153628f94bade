"""The game: turns levels into entities in one framework Scene and steps it at 60 Hz.

::

    game = Game()                      # the shipped levels; or Game([parse_text(...)])
    game.step({"right", "space"})      # one fixed step with these keys held
    game.state.coins, game.player_transform.x

The scene stays the same object for the whole run (a window runner holds it); levels are swapped
inside it by despawning one level's entities and spawning the next one's (see
:func:`.systems.level_flow`). A level that asks for another contact solver (``Level.solver``: a
level with a rope bridge needs the soft one, whose joints hinge its planks) gets it: the scene
switches solver between the two steps of the level change (``Scene.solver`` is settable between
steps), and back to the game's own for a level that asks for none.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from pathlib import Path

from framework import AABB, Circle, Hitbox, Polygon, RevoluteJoint, Scene, Transform, Velocity
from framework.character import CharacterController
from framework.components import Visual
from framework.input import Input
from framework.tiles import SLOPES, STEP, terrain_pieces

from . import art as art_colors
from . import systems
from .animations import SHEETS, animations
from .bridge import hang, plank_length
from .components import (
    ALL,
    ENEMY,
    HAZARD,
    ONE_WAY,
    PICKUP,
    PLAYER,
    SOLID,
    BridgePlank,
    Checkpoint,
    Coin,
    Enemy,
    GameState,
    Goal,
    Hazard,
    LevelPiece,
    MovingPlatform,
    Player,
    SwingingPlatform,
    SwingRope,
    Tuning,
)
from .demo import Autoplay
from .levels import Level, TerrainLine, bridge_planks, builtin_levels, load_level
from .terrain import DARK_DEPTH, GRASS_DEPTH, LIGHT_DEPTH, fill_pieces, grass_strips

__all__ = ["DT", "Game", "COLORS"]

DT = 1.0 / 60.0
COLORS = {
    "solid": (86, 98, 128), "oneway": (176, 134, 82), "spikes": (226, 70, 70), "player": (84, 176, 255),
    "enemy": (196, 84, 164), "coin": (255, 212, 64), "goal": (90, 224, 120), "checkpoint": (150, 150, 150),
    "platform": (214, 170, 96), "crate": (168, 112, 64), "barrel": (120, 84, 52), "rope": (150, 120, 80),
    "plank": (186, 140, 86),
}
PROP_MASK = SOLID | ONE_WAY | PLAYER | ENEMY  # crates and barrels: solid to everything that moves
PLAYER_MASK = SOLID | ONE_WAY | ENEMY | PICKUP | HAZARD
ART_TILE = 32.0  # the tile images (see art.py) are drawn for 32-unit tiles; other sizes get colours
IMAGES = {name: Path(__file__).with_name("images") / f"{name}.png" for name in (
    "ground", "ground_top", "plank", "player_right", "player_left", "enemy", "goal", "checkpoint",
    "checkpoint_on", *SLOPES, STEP, *SHEETS)}


class Game:
    """A run of the platformer over ``levels`` (paths or :class:`Level` objects; default: the
    shipped ones), in a new scene unless one is given. ``autoplay``: scripted input (see
    :mod:`.demo`) instead of the keyboard's. The scene's solver when the game is made is the
    game's own (:attr:`solver`): the levels that ask for none are played with it."""

    def __init__(
        self, levels: Sequence[Level | str | Path] | None = None, *, tuning: Tuning | None = None,
        scene: Scene | None = None, view: tuple[float, float] = (960.0, 540.0), start: int = 0,
        autoplay: Autoplay | None = None,
    ) -> None:
        if levels is None:
            levels = builtin_levels()
        self.levels = [lvl if isinstance(lvl, Level) else load_level(lvl) for lvl in levels]
        if not self.levels:
            raise ValueError("Game needs at least one level")
        self.tuning = tuning or Tuning()
        self.scene = scene if scene is not None else Scene()
        #: the contact solver of the levels that ask for none (``Level.solver`` None): the scene's
        self.solver = self.scene.solver
        self.state = GameState(view=view)
        self.scene.resources[GameState] = self.state
        self.scene.resources[Tuning] = self.tuning
        self.scene.resources[Game] = self
        self.autoplay = autoplay
        if autoplay is not None:
            self.scene.add_system(self._autoplay, before="movement")  # first: before anyone reads keys
        systems.install(self.scene)
        self.spawn_level(start)

    # --- levels ----------------------------------------------------------------------------------

    @property
    def level(self) -> Level:
        return self.levels[self.state.level_index]

    def clear_level(self) -> None:
        """Despawn every entity the current level spawned (at the end of the step, if stepping)."""
        scene = self.scene
        for e, _piece in scene.query(LevelPiece):
            if scene.exists(e):
                scene.despawn(e)
        self.state.player = None

    def solver_of(self, index: int) -> str:
        """The contact solver level ``index`` is played with: the one it asks for, else the game's."""
        return self.levels[index].solver or self.solver

    def use_solver_of(self, index: int) -> None:
        """Switch the scene to level ``index``'s solver: now between steps, or when the step under
        way ends (``Scene.after_step``); nothing if it has it."""
        want = self.solver_of(index)
        if self.scene.solver != want:
            self.scene.after_step(lambda scene: setattr(scene, "solver", want))

    def spawn_level(self, index: int) -> None:
        """Spawn level ``index``: its tiles, objects and the player at its start, in a scene running
        the level's solver (switched here between steps; during a step, the scene must have it
        already, as :func:`.systems.level_flow` sees to: else ``InvalidValue``, nothing spawned)."""
        if not 0 <= index < len(self.levels):
            raise ValueError(f"no level {index}: the game has {len(self.levels)}")
        if self.scene.solver != self.solver_of(index):
            self.scene.solver = self.solver_of(index)
        if self.state.player is not None:
            self.clear_level()
        level = self.levels[index]
        scene, tu, st = self.scene, self.tuning, self.state
        t = level.tile
        scene.gravity = (0.0, -tu.gravity * t)
        st.level_index, st.level_name, st.tile = index, level.name, t
        st.coins_in_level, st.goal_timer, st.pending, st.level_done = 0, 0.0, None, False
        st.bounds = (0.0, 0.0, *level.size)
        start = level.player
        st.checkpoint = (start.x, start.bottom)

        def piece(kind: str, *components) -> int:
            return scene.spawn(*components, LevelPiece(kind))

        art = st.art = t == ART_TILE and all(p.exists() for p in IMAGES.values())

        def look(image: str, color: str, z: int) -> Visual:
            return Visual(image=str(IMAGES[image]), z=z) if art else Visual(COLORS[color], z=z)

        def moving(animation: str, color: str, z: int) -> Visual:
            return Visual(animation=animations()[animation], z=z) if art else Visual(COLORS[color], z=z)

        # Terrain (solid cells and slopes): framework.tiles merges slope runs into convex pieces,
        # so nothing catches on a seam; a solid cell on its own stays one box per cell.
        for pc in terrain_pieces(level.tiles, t):
            if isinstance(pc.shape, AABB):
                (col, row), = pc.cells
                top = row == 0 or level.tiles[row - 1][col] != "solid"
                piece("solid", Transform(pc.x, pc.y), Hitbox(pc.shape, body="static", layer=SOLID),
                      look("ground_top" if top else "ground", "solid", 0))
                continue
            if not art:
                piece("slope", Transform(pc.x, pc.y), Hitbox(pc.shape, body="static", layer=SOLID),
                      Visual(COLORS["solid"], z=0))
                continue
            piece("slope", Transform(pc.x, pc.y), Hitbox(pc.shape, body="static", layer=SOLID))
            for col, row in pc.cells:  # the pictures, cell by cell
                kind = level.tiles[row][col]
                image = "ground_top" if kind == "solid" else kind
                # (a slope piece's cells all hold a tile)
                piece("slope", Transform(*level.cell_center(col, row)), Visual(image=str(IMAGES[image]), z=0))  # type: ignore[index]
        for line in level.terrain:  # drawn as lines: a chain, and pieces that draw the ground
            self._terrain(line, t, piece, art)
        for row, cells in enumerate(level.tiles):
            for col, kind in enumerate(cells):
                x, y = level.cell_center(col, row)
                if kind == "oneway":
                    # A slab on the top quarter of the cell, solid only from above.
                    piece(kind, Transform(x, y + 0.375 * t), Hitbox(
                        AABB(t, 0.25 * t), body="static", layer=ONE_WAY, one_way=True),
                        look("plank", kind, 0))
                elif kind == "spikes":
                    self._spikes(x, y - 0.5 * t, t, piece)
        for obj in level.objects:
            if obj.kind == "coin":
                piece("coin", Transform(obj.x, obj.y), Hitbox(
                    Circle(tu.coin_radius * t), body="static", sensor=True, layer=PICKUP, mask=PLAYER),
                    Coin(), moving("coin", "coin", 2))
            elif obj.kind in ("goal", "checkpoint"):
                w, h = (obj.width, obj.height) if obj.width > 0 and obj.height > 0 else (t, t)
                bottom = obj.bottom if obj.height > 0 else obj.y
                comp = Goal() if obj.kind == "goal" else Checkpoint()
                w = min(w, 0.5 * t) if obj.kind == "checkpoint" else w
                piece(obj.kind, Transform(obj.x, bottom + h * 0.5), Hitbox(
                    AABB(w, h), body="static", sensor=True, layer=PICKUP, mask=PLAYER), comp,
                    look(obj.kind, obj.kind, 1))
            elif obj.kind == "spikes":
                n = max(1, round(obj.width / t))
                for i in range(n):
                    x = obj.x - obj.width * 0.5 + (i + 0.5) * obj.width / n
                    self._spikes(x, obj.bottom, obj.width / n, piece)
            elif obj.kind == "platform":
                self._platform(obj, t, piece)
            elif obj.kind == "swing":
                self._swing(obj, t, piece)
            elif obj.kind == "bridge":
                self._bridge(obj, t, piece)
            elif obj.kind == "crate":
                s = tu.crate_size * t
                piece("crate", Transform(obj.x, obj.bottom + s * 0.5), Velocity(), Hitbox(
                    AABB(s, s), layer=SOLID, mask=PROP_MASK, mass=tu.crate_mass, friction=tu.prop_friction),
                    Visual(COLORS["crate"], z=2))
            elif obj.kind == "barrel":
                r = tu.barrel_radius * t
                piece("barrel", Transform(obj.x, obj.bottom + r), Velocity(), Hitbox(
                    Circle(r), layer=SOLID, mask=PROP_MASK, friction=tu.prop_friction),
                    Visual(COLORS["barrel"], z=2))
            elif obj.kind == "enemy":
                w, h = tu.enemy_size[0] * t, tu.enemy_size[1] * t
                speed = float(obj.props.get("speed", 2.0)) * t
                piece("enemy", Transform(obj.x, obj.bottom + h * 0.5), Velocity(), Hitbox(
                    AABB(w, h), body="kinematic", layer=ENEMY, mask=SOLID | ONE_WAY | PLAYER | ENEMY | HAZARD),
                    CharacterController(step_height=tu.step_height * t, solid_mask=SOLID | ONE_WAY | ENEMY),
                    Enemy(speed, int(obj.props.get("direction", -1))), moving("walk", "enemy", 3))
        st.coin_total_in_level = len(level.of_kind("coin"))
        w, h = tu.player_size[0] * t, tu.player_size[1] * t
        st.player = piece("player", Transform(start.x, start.bottom + h * 0.5), Velocity(),
                          Hitbox(AABB(w, h), body="kinematic", layer=PLAYER, mask=PLAYER_MASK),
                          CharacterController(step_height=tu.step_height * t, solid_mask=SOLID | ONE_WAY,
                                              push_mass=tu.push_mass),
                          Player(), moving("idle", "player", 4))
        systems.follow_camera(scene, 0.0)

    @staticmethod
    def _terrain(line: TerrainLine, t: float, piece, art: bool) -> None:
        """Terrain drawn as a line (:class:`.levels.TerrainLine`): its chain, one static segment a
        body (solid from outside, no catching at joints), and the pieces that draw it
        (:mod:`.terrain`): the ground's fill, and with the art, grass along its top."""
        for seg in line.chain().segments:
            piece("chain", Transform(0.0, 0.0), Hitbox(seg, body="static", layer=SOLID))
        looks = [(fill_pieces(line), art_colors.GROUND if art else COLORS["solid"], 0)]
        if art:
            light, grass, dark = LIGHT_DEPTH * t, GRASS_DEPTH * t, (GRASS_DEPTH - DARK_DEPTH) * t
            looks += [(grass_strips(line, 0.0, light), art_colors.GRASS_LIGHT, 1),
                      (grass_strips(line, light, dark), art_colors.GRASS, 1),
                      (grass_strips(line, dark, grass), art_colors.GRASS_DARK, 1)]
        for outlines, color, z in looks:
            for pts in outlines:
                x0, y0 = pts[0]  # (the piece's place: its first corner)
                try:
                    shape = Polygon([(x - x0, y - y0) for x, y in pts])
                except ValueError:
                    continue  # too thin to draw (a sliver under a near-vertical edge)
                piece("terrain", Transform(x0, y0), Hitbox(shape, body="static", sensor=True, layer=0, mask=0),
                      Visual(color, z=z))

    @staticmethod
    def _spikes(x: float, bottom: float, width: float, piece) -> None:
        # A triangle standing on the cell's floor, a bit narrower and lower than the cell.
        h = 0.55 * width
        tri = Polygon([(-0.42 * width, 0.0), (0.42 * width, 0.0), (0.0, h)])
        hitbox = Hitbox(tri, body="static", sensor=True, layer=HAZARD, mask=PLAYER | ENEMY)
        piece("spikes", Transform(x, bottom), hitbox, Hazard(), Visual(COLORS["spikes"], z=1))

    def _platform(self, obj, t: float, piece) -> None:
        one_way = bool(obj.props.get("one_way", True))
        dx, dy = float(obj.props.get("dx", 0.0)) * t, float(obj.props.get("dy", 0.0)) * t
        speed = float(obj.props.get("speed", 2.0)) * t
        pause = float(obj.props.get("pause", 0.5))
        piece("platform", Transform(obj.x, obj.y), Velocity(), Hitbox(
            AABB(obj.width, obj.height), body="kinematic", layer=ONE_WAY if one_way else SOLID, mask=ALL,
            one_way=one_way), MovingPlatform((obj.x, obj.y), (obj.x + dx, obj.y + dy), speed, pause),
            Visual(COLORS["platform"], z=1))

    def _swing(self, obj, t: float, piece) -> None:
        """A board hanging ``length`` tiles below its pivot (the rectangle is the board at rest,
        straight below the pivot), swinging as a pendulum (:class:`.SwingingPlatform`): a kinematic
        Polygon, since it turns with its rope (a box never turns). The period defaults to the
        pendulum's, ``2 pi sqrt(length / gravity)``, in tiles and the game's gravity. One-way
        unless the map says otherwise (``one_way`` false), like a moving platform."""
        one_way = bool(obj.props.get("one_way", True))
        length = float(obj.props["length"])
        period = obj.props.get("period")
        period = float(period) if period is not None else 2.0 * math.pi * math.sqrt(length / self.tuning.gravity)
        swing = SwingingPlatform(
            (obj.x, obj.y + length * t), length * t, math.radians(float(obj.props.get("angle", 30.0))), period,
            math.radians(float(obj.props.get("phase", 0.0))))
        x, y, theta = swing.pose(0.0)
        hw, hh = obj.width * 0.5, obj.height * 0.5
        board = Polygon([(-hw, -hh), (hw, -hh), (hw, hh), (-hw, hh)])
        piece("swing", Transform(x, y, theta), Velocity(), Hitbox(
            board, body="kinematic", layer=ONE_WAY if one_way else SOLID, mask=ALL, one_way=one_way),
            swing, Visual(COLORS["platform"], z=1))
        # The rope: drawn only (no layer, no mask: it meets nothing), from the pivot to the board.
        rope = Polygon([(-1.0, -swing.length + hh), (1.0, -swing.length + hh), (1.0, 0.0), (-1.0, 0.0)])
        piece("rope", Transform(*swing.pivot, theta), Velocity(), Hitbox(
            rope, body="kinematic", sensor=True, layer=0, mask=0), SwingRope(swing), Visual(COLORS["rope"], z=0))

    def _bridge(self, obj, t: float, piece) -> None:
        """A rope bridge (:mod:`.bridge`): ``planks`` dynamic planks (``Polygon`` boxes: they turn)
        hinged end to end by ``RevoluteJoint``s, the end ones to the anchors, spawned where the
        statics hang them (so the bridge starts at rest). The rectangle's left and right edges are
        the anchors, its top the deck's top there and its height the sag at rest; the hinges are on
        the planks' middle line, half a plank's thickness below the deck's top. A plank's layer is
        ``SOLID`` and its mask 0: the player and the walkers stand on it (their controllers block
        on its layer), and it meets nothing in the solver (not the ground at its ends, not the
        player, whose weight it takes from :func:`.systems.weigh_on_bridges`)."""
        planks = bridge_planks(obj, t)
        thickness = float(obj.props.get("thickness", 0.25)) * t
        mass = float(obj.props.get("mass", self.tuning.plank_mass))
        top = obj.y + obj.height * 0.5
        left, right = (obj.x - obj.width * 0.5, top - thickness * 0.5), (obj.x + obj.width * 0.5, top - thickness * 0.5)
        length = plank_length(obj.width, obj.height, planks)
        hinges = hang(left, right, planks, length, [1.0] * (planks - 1))
        box = Polygon.box(length, thickness)
        bodies = []
        for i in range(planks):
            (x0, y0), (x1, y1) = hinges[i], hinges[i + 1]
            bodies.append(piece("plank", Transform((x0 + x1) * 0.5, (y0 + y1) * 0.5, math.atan2(y1 - y0, x1 - x0)),
                                Velocity(), Hitbox(box, layer=SOLID, mask=0, mass=mass), BridgePlank(i, planks),
                                Visual(COLORS["plank"], z=1)))
        # (the joints go with their planks when the level is left: no LevelPiece of their own)
        scene = self.scene
        scene.spawn(RevoluteJoint(bodies[0], None, hinges[0]))
        for i in range(planks - 1):
            scene.spawn(RevoluteJoint(bodies[i], bodies[i + 1], hinges[i + 1]))
        scene.spawn(RevoluteJoint(bodies[-1], None, hinges[-1]))

    def _autoplay(self, scene: Scene, dt: float) -> None:
        playing = self.state.player is not None and self.state.pending is None
        # (this system is added only with an autoplay)
        scene.resources[Input].set_held(self.autoplay.keys(self) if playing else ())  # type: ignore[union-attr]

    # --- running ---------------------------------------------------------------------------------

    def step(self, keys: Iterable[str] | None = None) -> None:
        """One fixed step (1/60 s); ``keys``: exactly the keys held during it (None: unchanged)."""
        if keys is not None:
            self.scene.resources[Input].set_held(keys)
        self.scene.step(DT)

    @property
    def player(self) -> int:
        if self.state.player is None:
            raise RuntimeError("no player: the level is being changed")
        return self.state.player

    @property
    def player_transform(self) -> Transform:
        return self.scene.get(self.player, Transform)

    @property
    def player_state(self) -> Player:
        return self.scene.get(self.player, Player)

    def summary(self) -> dict:
        st = self.state
        return {
            "level": st.level_name, "level_index": st.level_index, "reached_goal": st.reached_goal,
            "levels_completed": st.levels_completed, "coins": st.coins, "deaths": st.deaths,
            "stomps": st.stomps,
        }

    def close(self) -> None:
        self.scene.close()

    def __enter__(self) -> Game:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
