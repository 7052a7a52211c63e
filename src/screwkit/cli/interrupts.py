"""Ctrl-C that arrives inside a C callback (numba's compiled-code cache notifier, llvmlite's
``_raw_object_cache_notify``, a ctypes callback) cannot propagate from there: Python prints
"Exception ignored on calling ctypes callback function" with a traceback and drops the
interrupt, so the run goes on. :func:`deliver_interrupts_from_callbacks` installs a
``sys.unraisablehook`` that, for a ``KeyboardInterrupt``, prints nothing and has a helper thread
interrupt the main thread again a moment later (``_thread.interrupt_main``), once the callback
has returned, so the interrupt lands in ordinary code and the command stops as on any other
Ctrl-C: one line, no traceback, no output file. (Interrupting from the hook itself would only
raise inside the hook, where it is dropped again.)"""

from __future__ import annotations

import _thread
import sys
import threading
from typing import Any

#: how long the helper thread waits before it interrupts the main thread again: long enough for
#: the callback to return, short against a person's Ctrl-C
REDELIVER_AFTER = 0.05


def _redeliver(wanted: threading.Event) -> None:
    while True:
        wanted.wait()
        wanted.clear()
        threading.Event().wait(REDELIVER_AFTER)
        _thread.interrupt_main()


def _hook(previous: Any, wanted: threading.Event) -> Any:
    def hook(unraisable: Any) -> None:
        if unraisable.exc_type is not None and issubclass(unraisable.exc_type,
                                                          KeyboardInterrupt):
            wanted.set()
            return
        previous(unraisable)

    hook.screwkit_interrupts = True  # type: ignore[attr-defined]
    return hook


def deliver_interrupts_from_callbacks() -> None:
    """Install the hook and its helper thread (once; the hook that was there before handles
    every other unraisable exception)."""
    if getattr(sys.unraisablehook, "screwkit_interrupts", False):
        return
    wanted = threading.Event()
    threading.Thread(target=_redeliver, args=(wanted,), name="screwkit-interrupts",
                     daemon=True).start()
    sys.unraisablehook = _hook(sys.unraisablehook, wanted)
