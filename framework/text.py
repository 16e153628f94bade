"""The :class:`Text` component: words on screen (a score, lives, a message, a name over a walker).

Plain, validated data, like :class:`~framework.components.Visual`: the render system
(:mod:`framework.render`) draws every entity's ``Text`` with pyglet labels; without a renderer it is
data a headless test can read (``scene.get(hud, Text).text``), and no GL module is loaded.

Two ways to place it:

- in the world (the default): at the entity's Transform plus ``offset`` (world units), moving
  with the entity and the camera, scaled by its zoom (``size`` is in world units, pixels at zoom 1);
- on the screen (``screen=True``): at ``offset`` pixels from a ``corner`` of the view, where the
  camera never moves it (a HUD); such an entity needs no Transform.

Every field may change at any time (``hud_text.text = f"coins {n}"`` in a game system); a bad value
is an :class:`~framework.validation.InvalidValue` (a ``ValueError``) naming it, when it is set.
"""

from __future__ import annotations

from typing import Any

from .validation import InvalidValue, positive, vector2

__all__ = ["ANCHORS_X", "ANCHORS_Y", "CORNERS", "Text"]

#: Which point of the text sits at its position, across and up.
ANCHORS_X = ("left", "center", "right")
ANCHORS_Y = ("bottom", "baseline", "center", "top")
#: The points of the view a screen text's ``offset`` counts from (y up).
CORNERS = ("bottom_left", "bottom_right", "top_left", "top_right", "center")

_UNSET = object()


def _color(value: Any) -> tuple[int, int, int, int]:
    try:
        parts = tuple(value)
    except TypeError:
        raise InvalidValue(f"Text color must be (r, g, b) or (r, g, b, a), got {value!r}") from None
    if len(parts) not in (3, 4) or not all(isinstance(c, int) and not isinstance(c, bool) and 0 <= c <= 255
                                           for c in parts):
        raise InvalidValue(f"Text color must be 3 or 4 ints in 0..255, got {value!r}")
    return (parts[0], parts[1], parts[2], parts[3] if len(parts) == 4 else 255)


def _choice(name: str, value: object, allowed: tuple[str, ...]) -> str:
    if not isinstance(value, str) or value not in allowed:
        raise InvalidValue(f"Text {name} must be one of {allowed}, got {value!r}")
    return value


class Text:
    """A text the render system draws for its entity.

    ``text``: what it says, one line. ``size``: the font size (points: pixels on
    screen, or world units in the world), finite and > 0. ``color``: (r, g, b) or (r, g, b, a),
    0-255. ``screen``: placed on the screen (a HUD) instead of in the world. ``offset``: from the
    entity's Transform (world), or from ``corner`` of the view in pixels, y up (screen).
    ``corner``: one of :data:`CORNERS` (screen texts). ``anchor_x``, ``anchor_y``: which point of
    the text is at its position (:data:`ANCHORS_X`, :data:`ANCHORS_Y`; None, the default: the
    corner's sides for a screen text, so it stays inside the view, else left and bottom). ``z``: higher draws on top
    of lower among texts (texts draw over the scene's sprites). ``visible=False`` hides it.
    ``font``: a font family name (``None``: pyglet's default)."""

    __slots__ = ("_text", "_size", "_color", "_screen", "_offset", "_corner", "_anchor_x", "_anchor_y", "_z",
                 "_visible", "_font", "version")
    _text: str
    _size: float
    _color: tuple[int, int, int, int]
    _screen: bool
    _offset: tuple[float, float]
    _corner: str
    _anchor_x: str | None
    _anchor_y: str | None
    _z: int
    _visible: bool
    _font: str | None
    version: int

    def __init__(
        self,
        text: str = "",
        *,
        size: float = 14.0,
        color: Any = (255, 255, 255),
        screen: bool = False,
        offset: Any = (0.0, 0.0),
        corner: str = "bottom_left",
        anchor_x: str | None = None,
        anchor_y: str | None = None,
        z: int = 0,
        visible: bool = True,
        font: str | None = None,
    ) -> None:
        self.version = 0  # bumped by every change: the renderer updates its label when it differs
        self.text = text
        self.size = size
        self.color = color
        self.screen = screen
        self.offset = offset
        self.corner = corner
        self.anchor_x = anchor_x
        self.anchor_y = anchor_y
        self.z = z
        self.visible = visible
        self.font = font

    def __repr__(self) -> str:
        where = f"screen, {self._corner} + {self._offset}" if self._screen else f"world + {self._offset}"
        return f"Text({self._text!r}, size={self._size:g}, {where})"

    def _set(self, name: str, value: Any) -> None:
        # The same value again is no change: a system may write the HUD's text every step.
        if getattr(self, name, _UNSET) != value:
            object.__setattr__(self, name, value)
            self.version += 1

    @property
    def text(self) -> str:
        return self._text

    @text.setter
    def text(self, value: str) -> None:
        if not isinstance(value, str):
            raise InvalidValue(f"Text text must be a str, got {value!r}")
        if "\n" in value or "\r" in value:
            raise InvalidValue(f"Text text is one line (a Text per line), got {value!r}")
        self._set("_text", value)

    @property
    def size(self) -> float:
        return self._size

    @size.setter
    def size(self, value: float) -> None:
        self._set("_size", positive("Text size", value))

    @property
    def color(self) -> tuple[int, int, int, int]:
        return self._color

    @color.setter
    def color(self, value: Any) -> None:
        self._set("_color", _color(value))

    @property
    def screen(self) -> bool:
        return self._screen

    @screen.setter
    def screen(self, value: bool) -> None:
        if not isinstance(value, bool):
            raise InvalidValue(f"Text screen must be True or False, got {value!r}")
        self._set("_screen", value)

    @property
    def offset(self) -> tuple[float, float]:
        return self._offset

    @offset.setter
    def offset(self, value: Any) -> None:
        self._set("_offset", vector2("Text offset", value))

    @property
    def corner(self) -> str:
        return self._corner

    @corner.setter
    def corner(self, value: str) -> None:
        self._set("_corner", _choice("corner", value, CORNERS))

    @property
    def anchor_x(self) -> str:
        """Which point across is at its position; unset (None): the corner's side for a screen
        text (``"right"`` at a right corner, ``"center"`` at the centre), else ``"left"``."""
        if self._anchor_x is not None:
            return self._anchor_x
        if self._screen and self._corner.endswith("right"):
            return "right"
        return "center" if self._screen and self._corner == "center" else "left"

    @anchor_x.setter
    def anchor_x(self, value: str | None) -> None:
        self._set("_anchor_x", None if value is None else _choice("anchor_x", value, ANCHORS_X))

    @property
    def anchor_y(self) -> str:
        """Which point up is at its position; unset (None): the corner's side for a screen text
        (``"top"`` at a top corner, so a HUD line at ``top_left`` hangs inside the view,
        ``"center"`` at the centre), else ``"bottom"``."""
        if self._anchor_y is not None:
            return self._anchor_y
        if self._screen and self._corner.startswith("top"):
            return "top"
        return "center" if self._screen and self._corner == "center" else "bottom"

    @anchor_y.setter
    def anchor_y(self, value: str | None) -> None:
        self._set("_anchor_y", None if value is None else _choice("anchor_y", value, ANCHORS_Y))

    @property
    def z(self) -> int:
        return self._z

    @z.setter
    def z(self, value: int) -> None:
        if isinstance(value, bool) or not isinstance(value, int):
            raise InvalidValue(f"Text z must be an int, got {value!r}")
        self._set("_z", value)

    @property
    def visible(self) -> bool:
        return self._visible

    @visible.setter
    def visible(self, value: bool) -> None:
        if not isinstance(value, bool):
            raise InvalidValue(f"Text visible must be True or False, got {value!r}")
        self._set("_visible", value)

    @property
    def font(self) -> str | None:
        return self._font

    @font.setter
    def font(self, value: str | None) -> None:
        if value is not None and (not isinstance(value, str) or not value):
            raise InvalidValue(f"Text font must be a font family name or None, got {value!r}")
        self._set("_font", value)
