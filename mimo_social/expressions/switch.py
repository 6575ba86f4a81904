"""Face textures in the model and the per-agent expression switch.

The seven face images (:mod:`.faces`) become seven cube textures shared by every agent: the face
sits on the cube side that MuJoCo projects onto the head sphere's front (+x), the other sides are
plain skin. Every agent's head has its own material; switching an expression points that
material at another texture (``model.mat_texid``), which a renderer picks up on its next frame
without re-uploading anything.
"""

from __future__ import annotations

import mujoco
import numpy as np

from .faces import EXPRESSIONS, SKIN_RGB, face_images

__all__ = ["FaceTextures", "EXPRESSIONS", "FACE_TEXTURE_SIZE"]

FACE_TEXTURE_SIZE = 128
_RGB = mujoco.mjtTextureRole.mjTEXROLE_RGB


def _cube_data(face: np.ndarray) -> np.ndarray:
    """Six square sides stacked vertically in MuJoCo's order: +x, -x, +y, -y, +z, -z."""
    n = face.shape[0]
    skin = np.empty((n, n, 3), np.uint8)
    skin[:] = SKIN_RGB
    # Seen from the front, MuJoCo shows the +x side's image turned a quarter clockwise
    # (checked by rendering a four-colour test pattern); store it turned back.
    front = np.ascontiguousarray(np.rot90(face, 1))
    return np.concatenate([front, skin, skin, skin, skin, skin], axis=0)


class FaceTextures:
    """The shared face textures of one world."""

    names = tuple(f"face_{e}" for e in EXPRESSIONS)

    def __init__(self, size: int = FACE_TEXTURE_SIZE):
        self.size = size
        self._tex_ids: np.ndarray | None = None

    def add_to(self, spec: mujoco.MjSpec) -> None:
        images = face_images(self.size)
        for name, img in zip(self.names, images):
            tex = spec.add_texture(name=name, type=mujoco.mjtTexture.mjTEXTURE_CUBE,
                                   width=self.size, height=6 * self.size, nchannel=3)
            tex.data = _cube_data(img).tobytes()

    def bind_material(self, material) -> None:
        material.textures[_RGB] = self.names[0]
        material.rgba = [1.0, 1.0, 1.0, 1.0]
        material.specular = 0.1
        material.shininess = 0.1

    def _ids(self, model) -> np.ndarray:
        if self._tex_ids is None:
            self._tex_ids = np.array([model.texture(n).id for n in self.names])
        return self._tex_ids

    def show(self, model, material_id: int, expression: int) -> None:
        if not 0 <= int(expression) < len(EXPRESSIONS):
            raise ValueError(f"expression id {expression} out of range; allowed 0..{len(EXPRESSIONS) - 1} "
                             f"({', '.join(f'{i}={e}' for i, e in enumerate(EXPRESSIONS))})")
        model.mat_texid[material_id, _RGB] = self._ids(model)[int(expression)]

    def shown(self, model, material_id: int) -> int:
        tex = model.mat_texid[material_id, _RGB]
        return int(np.flatnonzero(self._ids(model) == tex)[0])

    def __getstate__(self):
        return {"size": self.size}

    def __setstate__(self, state):
        self.__init__(state["size"])
