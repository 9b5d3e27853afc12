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
    """Call ``listener(filename, size_bytes)`` when an upload to ``gui_api`` (the GUI API of a
    viser server or of one of its clients) is refused for its size."""
    _LISTENERS[gui_api] = listener


def _tell(api, filename: str, size: int) -> None:
    listener = _LISTENERS.get(api)
    if listener is not None:
        listener(filename, size)


def bound_uploads() -> None:
    """Bound every viser server's uploads to :data:`UPLOAD_LIMIT_BYTES`, while they stream
    (installed once per process, on viser's ``GuiApi``: its handlers are looked up when a
    server is made)."""
    from viser._gui_api import GuiApi

    start, part = GuiApi._handle_file_transfer_start, GuiApi._handle_file_transfer_part
    if getattr(start, "_filletfold", False):
        return

    @functools.wraps(start)
    def checked_start(self, client_id, message):
        mine = message.source_component_uuid in self._gui_input_handle_from_uuid
        if mine and message.size_bytes > UPLOAD_LIMIT_BYTES:  # announced too large: nothing is kept
            _tell(self, message.filename, int(message.size_bytes))
            return None
        return start(self, client_id, message)

    @functools.wraps(part)
    def checked_part(self, client_id, message):
        state = self._current_file_upload_states.get(message.transfer_uuid)
        if state is not None:
            after = state["transferred_bytes"] + len(message.content)
            if after > min(UPLOAD_LIMIT_BYTES, state["total_bytes"]):  # more than announced
                self._current_file_upload_states.pop(message.transfer_uuid, None)  # parts freed
                _tell(self, state["filename"], after)
                return None
        return part(self, client_id, message)

    checked_start._filletfold = checked_part._filletfold = True
    GuiApi._handle_file_transfer_start = checked_start
    GuiApi._handle_file_transfer_part = checked_part
