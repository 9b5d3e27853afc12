"""A surface patch's identity: its kind and the mesh element it belongs to.

Every face of a crease pattern lies on one smooth patch of the folded surface: the cylinder of
a mesh edge, the conical fillet of an edge beside a sharp vertex, the cone of a mesh vertex, or
the flat piece of a mesh face. :class:`Patch` is that record, ``(kind, index)``. A pattern
keeps each face's patch by its name, ``str(patch)`` (``"cone 3"``, ``"cylinder 12"``), the form
FOLD files carry under ``filletfold:faces_patch``; this module is the one place that makes
names and reads them back (:meth:`Patch.parse`, and :func:`patch_kinds` /
:func:`patch_indices` for a whole pattern's faces at once).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

#: The kinds of patch, and the mesh element each one's index counts.
PATCH_KINDS = {"cylinder": "edge", "fillet": "edge", "cone": "vertex", "face": "face"}
#: The kinds whose surface is ruled (developable by its rulings); faces are flat.
RULED_KINDS = ("cylinder", "fillet", "cone")


class Patch(NamedTuple):
    """One patch: ``kind`` (a key of :data:`PATCH_KINDS`) and ``index`` (the mesh edge,
    vertex or face). ``str(patch)`` is its name, ``"<kind> <index>"``."""

    kind: str
    index: int

    def __str__(self) -> str:
        return f"{self.kind} {self.index}"

    @classmethod
    def parse(cls, name: str) -> Patch:
        """The patch of a name ``"<kind> <index>"``.

        Raises
        ------
        ValueError
            When ``name`` is not a known kind and a non-negative integer.
        """
        parts = str(name).split()
        if len(parts) != 2 or parts[0] not in PATCH_KINDS or not parts[1].isdigit():
            raise ValueError(
                f"patch {name!r} is not 'cone <vertex>', 'cylinder <edge>', 'fillet <edge>' "
                "or 'face <face>'"
            )
        return cls(parts[0], int(parts[1]))


def patch_names(kind: str, indices) -> list[str]:
    """The names of the patches of one ``kind`` with ``indices`` (ints)."""
    return [f"{kind} {int(i)}" for i in indices]


def patch_kind(name: str, default: str = "") -> str:
    """The kind of a patch name: its first word (``"cone 3"`` -> ``"cone"``); ``default`` for
    an empty name."""
    words = str(name).split()
    return words[0] if words else default


def patch_kinds(names) -> np.ndarray:
    """(n,) str: the kind of each of ``names`` (:func:`patch_kind`; each distinct name read
    once, a pattern has many faces per patch)."""
    kind = {name: patch_kind(name) for name in dict.fromkeys(names)}
    return np.array([kind[name] for name in names], dtype="<U8")


def patch_indices(names) -> np.ndarray:
    """(n,) int64: the element index of each of ``names`` (-1 where a name has none)."""
    index = {}
    for name in dict.fromkeys(names):
        parts = str(name).split()
        index[name] = int(parts[1]) if len(parts) == 2 and parts[1].isdigit() else -1
    return np.fromiter((index[name] for name in names), dtype=np.int64, count=len(names))
