"""What the render system puts on the GPU: a vertex list per drawable, its pose in a table.

Each drawable is a pyglet vertex list in the renderer's batch, under a :class:`LayerGroup` per
``Visual.z`` (one draw call per layer: pyglet multi-draws a group's vertex lists in one call).
Its vertices never change while it moves: a filled hitbox's vertices are its outline's triangles
about the hitbox origin, a sprite's the corners of a unit square. Where each drawable is (position,
rotation), what part of the atlas it shows and its size, and whether it is shown, live in one
float table with a row per drawable (a *slot*), a float texture the vertex shader reads with
``texelFetch``. So a frame writes numpy columns into that table and uploads it once, however many
drawables moved, turned or changed animation frame: no Python per drawable.

Slot row, three RGBA float texels: ``(x, y, cos, sin)``, ``(u0, v0, u1, v1)`` (sprites), ``(width,
height, shown, 0)`` (a sprite's size in pixels, a disc's radius twice). A filled circle is a disc:
two triangles whose fragments beyond the radius are discarded, exact at every zoom.
"""

from __future__ import annotations

import ctypes
from typing import Any

import numpy as np
from pyglet import gl
from pyglet.graphics import Group

from .drawables import fan_indices

__all__ = ["DISC", "DISC_QUAD", "FILL", "SLOTS_PER_ROW", "SPRITE", "SPRITE_QUAD", "InstanceTable", "LayerGroup",
           "program", "vertex_list"]

SLOTS_PER_ROW = 1024  # slots in one row of the table texture (3 texels each)

# ``draw_as`` (a vertex list's mode): 0 a filled outline (``local`` its triangles about the hitbox
# origin), 1 a sprite
# (``local`` the corners of the unit square, scaled by the slot's size), 2 a disc (``local`` the
# corners of the square [-1, 1]^2, scaled by the slot's radius; the fragment shader keeps what is
# within the radius: a circle exact at every zoom, in two triangles).
_VERTEX = """#version 150 core
in vec2 local;
in vec4 colors;
in float slot;
in float draw_as;
out vec4 vertex_colors;
out vec2 texture_coords;
out float vertex_mode;
uniform sampler2D instances;
uniform WindowBlock
{
    mat4 projection;
    mat4 view;
} window;
void main()
{
    int s = int(slot + 0.5);
    ivec2 at = ivec2((s % 1024) * 3, s / 1024);
    vec4 pose = texelFetch(instances, at, 0);
    vec4 size = texelFetch(instances, at + ivec2(2, 0), 0);
    vec2 p = local;
    texture_coords = local;
    if (draw_as > 0.5) {
        p = draw_as > 1.5 ? local * size.xy : (local - 0.5) * size.xy;
        if (draw_as < 1.5) {
            vec4 uv = texelFetch(instances, at + ivec2(1, 0), 0);
            texture_coords = mix(uv.xy, uv.zw, local);
        }
    }
    vec2 world = pose.xy + vec2(pose.z * p.x - pose.w * p.y, pose.w * p.x + pose.z * p.y);
    gl_Position = size.z > 0.5 ? window.projection * window.view * vec4(world, 0.0, 1.0)
                               : vec4(2.0, 2.0, 2.0, 1.0);  // hidden: outside the clip volume
    vertex_colors = colors;
    vertex_mode = draw_as;
}
"""

_FRAGMENT = """#version 150 core
in vec4 vertex_colors;
in vec2 texture_coords;
in float vertex_mode;
out vec4 final_colors;
uniform sampler2D atlas;
void main()
{
    if (vertex_mode > 1.5) {
        if (dot(texture_coords, texture_coords) > 1.0) discard;
        final_colors = vertex_colors;
    } else {
        final_colors = vertex_mode > 0.5 ? texture(atlas, texture_coords) * vertex_colors : vertex_colors;
    }
}
"""

_programs: dict[Any, Any] = {}


def program() -> Any:
    """The render system's shader program in the current GL context (made once per context)."""
    ctx = gl.current_context
    prog = _programs.get(ctx)
    if prog is None:
        if ctx is None:
            raise RuntimeError("the render system's shader needs a current GL context")
        prog = ctx.create_program((_VERTEX, "vertex"), (_FRAGMENT, "fragment"))
        prog.use()
        prog["atlas"] = 0
        prog["instances"] = 1
        prog.stop()
        _programs[ctx] = prog
    return prog


class InstanceTable:
    """The slot table: a numpy mirror (``rows`` = slots x 3 x 4 float32) and its float texture.

    :meth:`upload` sends the rows in use when something changed (:attr:`dirty`)."""

    def __init__(self) -> None:
        self.capacity = 0
        self.rows = np.zeros((0, 3, 4), dtype=np.float32)
        self.dirty = True
        self.used = 0  # slots below this may be in use: the rows uploaded
        self._texture_id: int | None = None
        self._texture_rows = 0

    def grow(self, capacity: int) -> None:
        """Hold at least ``capacity`` slots (a whole number of texture rows)."""
        if capacity <= self.capacity:
            return
        rows_needed = -(-capacity // SLOTS_PER_ROW)
        new = max(rows_needed * SLOTS_PER_ROW, 2 * self.capacity)
        rows = np.zeros((new, 3, 4), dtype=np.float32)
        rows[: self.capacity] = self.rows
        self.rows, self.capacity = rows, new
        self.dirty = True

    def texture_id(self) -> int:
        """The table's texture, with every slot row in use uploaded if it changed."""
        texture_rows = self.capacity // SLOTS_PER_ROW
        if self._texture_id is None or self._texture_rows != texture_rows:
            if self._texture_id is not None:
                gl.glDeleteTextures(1, ctypes.byref(gl.GLuint(self._texture_id)))
            tex = gl.GLuint()
            gl.glGenTextures(1, ctypes.byref(tex))
            self._texture_id = int(tex.value)
            gl.glBindTexture(gl.GL_TEXTURE_2D, self._texture_id)
            gl.glTexImage2D(gl.GL_TEXTURE_2D, 0, gl.GL_RGBA32F, SLOTS_PER_ROW * 3, max(texture_rows, 1), 0,
                            gl.GL_RGBA, gl.GL_FLOAT, None)
            for name in (gl.GL_TEXTURE_MIN_FILTER, gl.GL_TEXTURE_MAG_FILTER):
                gl.glTexParameteri(gl.GL_TEXTURE_2D, name, gl.GL_NEAREST)
            gl.glBindTexture(gl.GL_TEXTURE_2D, 0)
            self._texture_rows = texture_rows
            self.dirty = True
        if self.dirty and self.used:
            rows = -(-self.used // SLOTS_PER_ROW)
            data = self.rows[: rows * SLOTS_PER_ROW]
            gl.glBindTexture(gl.GL_TEXTURE_2D, self._texture_id)
            gl.glTexSubImage2D(gl.GL_TEXTURE_2D, 0, 0, 0, SLOTS_PER_ROW * 3, rows, gl.GL_RGBA, gl.GL_FLOAT,
                               data.ctypes.data_as(ctypes.POINTER(gl.GLfloat)))
            gl.glBindTexture(gl.GL_TEXTURE_2D, 0)
        self.dirty = False
        return self._texture_id

    def delete(self) -> None:
        if self._texture_id is not None:
            gl.glDeleteTextures(1, ctypes.byref(gl.GLuint(self._texture_id)))
            self._texture_id = None
            self._texture_rows = 0


class LayerGroup(Group):
    """One ``z`` layer: binds the program, the atlas (unit 0) and the slot table (unit 1); blends."""

    def __init__(self, z: int, textures: Any) -> None:
        super().__init__(order=z)
        self.z = z
        self.textures = textures  # an object with atlas_texture() and table_texture()
        self.program = program()

    def set_state(self) -> None:
        self.program.use()
        gl.glActiveTexture(gl.GL_TEXTURE1)
        gl.glBindTexture(gl.GL_TEXTURE_2D, self.textures.table_texture())
        gl.glActiveTexture(gl.GL_TEXTURE0)
        gl.glBindTexture(gl.GL_TEXTURE_2D, self.textures.atlas_texture())
        gl.glEnable(gl.GL_BLEND)
        gl.glBlendFunc(gl.GL_SRC_ALPHA, gl.GL_ONE_MINUS_SRC_ALPHA)

    def unset_state(self) -> None:
        gl.glDisable(gl.GL_BLEND)
        gl.glActiveTexture(gl.GL_TEXTURE1)
        gl.glBindTexture(gl.GL_TEXTURE_2D, 0)
        gl.glActiveTexture(gl.GL_TEXTURE0)
        gl.glBindTexture(gl.GL_TEXTURE_2D, 0)
        self.program.stop()

    def __eq__(self, other: object) -> bool:
        return self is other

    def __hash__(self) -> int:
        return id(self)


FILL, SPRITE, DISC = 0, 1, 2  # a vertex list's mode (see the vertex shader)


def vertex_list(batch: Any, group: LayerGroup, local: np.ndarray, color: tuple[int, int, int, int], slot: int,
                mode: int) -> Any:
    """A drawable's indexed vertex list: the convex outline ``local`` (flat x, y pairs, in order)
    as a fan of triangles, one colour, its slot, its mode. Indexed, each outline point runs the
    vertex shader once (a box 4 times, not 6; a hexagon 6, not 12)."""
    n = local.size // 2
    return group.program.vertex_list_indexed(
        n, gl.GL_TRIANGLES, fan_indices(n), batch, group,
        local=("f", local.tolist()), colors=("Bn", tuple(color) * n),
        slot=("f", (float(slot),) * n), draw_as=("f", (float(mode),) * n))


SPRITE_QUAD = np.array([0, 0, 1, 0, 1, 1, 0, 1], dtype=np.float64)  # the unit square's corners, in order
DISC_QUAD = 2.0 * SPRITE_QUAD - 1.0  # the square [-1, 1]^2
