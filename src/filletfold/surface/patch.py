"""A surface patch's identity: its kind and the mesh element it belongs to.

Every face of a crease pattern lies on one smooth patch of the folded surface: the cylinder of
a mesh edge, the conical fillet of an edge beside a sharp vertex, the cone of a mesh vertex, or
the flat piece of a mesh face. :class:`Patch` is that record, ``(kind, index)``, and pieces and
patterns keep one per face. Its name, ``str(patch)`` (``"cone 3"``, ``"cylinder 12"``), is what
files carry (FOLD's ``filletfold:faces_patch``, OBJ groups, 3dm objects); :func:`as_patch` reads
a name back. :func:`patch_kinds`, :func:`patch_indices`, :func:`kind_indices` and :func:`patch_ids`
give a whole pattern's faces at once.
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


def patches_of(kind: str, indices) -> list[Patch]:
    """The patches of one ``kind`` with ``indices`` (ints)."""
    return [Patch(kind, int(i)) for i in indices]


def patch_kind(patch, default: str = "") -> str:
    """The kind of a patch, or of a patch name: its first word (``"cone 3"`` -> ``"cone"``);
    ``default`` for an empty name."""
    if isinstance(patch, Patch):
        return patch.kind
    words = str(patch).split()
    return words[0] if words else default


def patch_kinds(patches) -> np.ndarray:
    """(n,) str: the kind of each of ``patches`` (:func:`patch_kind`; each distinct one read
    once, a pattern has many faces per patch)."""
    kind = {p: patch_kind(p) for p in dict.fromkeys(patches)}
    return np.array([kind[p] for p in patches], dtype="<U8")


def patch_indices(patches) -> np.ndarray:
    """(n,) int64: the element index of each of ``patches`` (-1 where a name has none)."""
    index = {}
    for p in dict.fromkeys(patches):
        if isinstance(p, Patch):
            index[p] = p.index
            continue
        parts = str(p).split()
        index[p] = int(parts[1]) if len(parts) == 2 and parts[1].isdigit() else -1
    return np.fromiter((index[p] for p in patches), dtype=np.int64, count=len(patches))


def kind_indices(patches, kind: str) -> np.ndarray:
    """(n,) int64: the element index of each of ``patches`` of ``kind`` (``"cone"``, ...), -1
    for the others."""
    if not len(patches):
        return np.zeros(0, dtype=np.int64)
    return np.where(patch_kinds(patches) == kind, patch_indices(patches), -1)


def patch_ids(patches) -> np.ndarray:
    """(n,) int64: the same number for equal patches, numbered in order of their first face
    (records or names alike: a pattern read from a file holds the names it carries)."""
    ids: dict = {}
    return np.fromiter(
        (ids.setdefault(p, len(ids)) for p in patches), dtype=np.int64, count=len(patches)
    )


def as_patch(value) -> Patch | str:
    """``value`` as a :class:`Patch` when it is one or names one (``"cone 3"``), else the
    string itself (a foreign file's patch name, which the certificate names as wrong)."""
    if isinstance(value, Patch):
        return value
    try:
        return Patch.parse(value)
    except ValueError:
        return str(value)
