"""Uploads bounded while they stream (issue 30).

viser buffers an uploaded file's parts until the last one arrives and only then hands the app
its bytes, so the app's size check came after a 1 GB upload had been held (2.3 GB). The guard
installed by :func:`bound_uploads` checks the size a client announces before any part is kept,
and the bytes each part adds, against :data:`~filletfold.app.session.UPLOAD_LIMIT_BYTES`: a
transfer over it is dropped at once (its buffered parts freed, later parts ignored) and the
app is told (:func:`on_refused`), so the page shows why.
"""

from __future__ import annotations

import functools
import weakref

from .session import UPLOAD_LIMIT_BYTES

__all__ = ["bound_uploads", "on_refused"]

#: The function told of a refused upload, per viser GUI API object: ``(filename, size)``.
_LISTENERS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def on_refused(gui_api, listener) -> None:
    """Call ``listener(filename, size_bytes)`` when an upload to ``gui_api`` (a viser server's
    GUI API) is refused for its size."""
    _LISTENERS[gui_api] = listener


def _refuse(api, transfer_uuid: str, filename: str, size: int) -> None:
    api._current_file_upload_states.pop(transfer_uuid, None)  # its parts freed
    listener = _LISTENERS.get(api)
    if listener is not None:
        listener(filename, size)


def bound_uploads(limit: int = UPLOAD_LIMIT_BYTES) -> None:
    """Bound every viser server's uploads to ``limit`` bytes, while they stream (installed
    once per process, on viser's ``GuiApi``: its handlers are looked up when a server is
    made)."""
    from viser._gui_api import GuiApi

    if getattr(GuiApi._handle_file_transfer_start, "_filletfold_limit", None) == limit:
        return
    start = getattr(GuiApi._handle_file_transfer_start, "_filletfold_original", None)
    part = getattr(GuiApi._handle_file_transfer_part, "_filletfold_original", None)
    start = start or GuiApi._handle_file_transfer_start
    part = part or GuiApi._handle_file_transfer_part

    @functools.wraps(start)
    def checked_start(self, client_id, message):
        if message.size_bytes > limit:  # announced too large: nothing of it is kept
            listener = _LISTENERS.get(self)
            if listener is not None:
                listener(message.filename, int(message.size_bytes))
            return None
        return start(self, client_id, message)

    @functools.wraps(part)
    def checked_part(self, client_id, message):
        state = self._current_file_upload_states.get(message.transfer_uuid)
        if state is not None:
            after = state["transferred_bytes"] + len(message.content)
            if after > min(limit, state["total_bytes"]):  # more than it announced, or allowed
                _refuse(self, message.transfer_uuid, state["filename"], after)
                return None
        return part(self, client_id, message)

    for wrapped, original in ((checked_start, start), (checked_part, part)):
        wrapped._filletfold_limit = limit
        wrapped._filletfold_original = original
    GuiApi._handle_file_transfer_start = checked_start
    GuiApi._handle_file_transfer_part = checked_part
