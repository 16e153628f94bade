"""Effects: what a scene simulates. A scene assembles only the stages its effects call for, so it
pays for nothing it does not use (see docs/effects.md)."""

from __future__ import annotations

from collections.abc import Iterable

from .validation import InvalidValue

__all__ = ["DEFAULT_EFFECTS", "EFFECTS", "resolve_effects"]

# Each effect, with the effects it needs.
EFFECTS: dict[str, tuple[str, ...]] = {
    "movement": (),                          # integrate Velocity
    "gravity": ("movement",),                # accelerate dynamic bodies by Scene.gravity
    "detection": (),                         # broad + narrow phase: which hitboxes overlap
    "events": ("detection",),                # every pair's started / ongoing / ended events
    "response": ("detection",),              # push bodies apart, slide, bounce
    "friction": ("response",),               # Coulomb friction between hitboxes that have some
    "rotation": ("response",),               # contacts turn bodies: boxes and polygons tip, circles roll
    "continuous": ("movement", "detection"),  # sweep Hitbox(ccd=True) bodies
    "character": (),                         # move CharacterController bodies (move and slide)
    "rendering": (),                         # the render stage (a renderer must be attached)
    "debug_overlay": ("rendering",),         # hitboxes, contacts, cells, rays on screen
    "sleeping": (),                          # bodies at rest sleep: no work until woken
}
DEFAULT_EFFECTS = frozenset({"movement", "gravity", "detection", "events", "response", "friction", "rotation",
                             "continuous", "character", "sleeping"})


def resolve_effects(effects: Iterable[str] | None) -> frozenset[str]:
    """The declared effects plus everything they need; ``ValueError`` for an unknown one."""
    if effects is None:
        return DEFAULT_EFFECTS
    if isinstance(effects, str):
        raise InvalidValue(f"effects must be a collection of names, got the string {effects!r}")
    wanted = list(effects)
    out: set[str] = set()
    while wanted:
        name = wanted.pop()
        if name not in EFFECTS:
            raise InvalidValue(f"unknown effect {name!r}; known effects are {sorted(EFFECTS)}")
        if name not in out:
            out.add(name)
            wanted.extend(EFFECTS[name])
    return frozenset(out)
