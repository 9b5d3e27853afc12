"""The browser app (``filletfold app``): viser front end over a GUI-free session.

:class:`AppSession` holds the state and is usable without viser; :func:`run_app` (needs the
``app`` extra, ``pip install 'filletfold[app]'``) starts the page.
"""

from __future__ import annotations

from .server import AppServer, AppView, run_app
from .session import UPLOAD_LIMIT_BYTES, AppSession

__all__ = ["UPLOAD_LIMIT_BYTES", "AppServer", "AppSession", "AppView", "run_app"]
