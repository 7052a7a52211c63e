"""A studio served in-process on a free port, for the studio tests (imported by name: a
``from conftest import`` would pick whichever conftest loaded first when several test folders
run together)."""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest

from screwkit.studio.server import Studio, bind, make_server, new_studio, url_of

EXAMPLES = Path(__file__).parents[2] / "examples"


@dataclass
class Served:
    studio: Studio
    url: str
    spec: Path
    server: Any

    @property
    def base(self) -> str:
        return self.url.split("?")[0].rstrip("/")

    @property
    def ws_url(self) -> str:
        return self.base.replace("http://", "ws://") + f"/ws?token={self.studio.token}"


def serve(spec: Path, save_as: Path | None = None) -> Iterator[Served]:
    studio = new_studio(spec, save_as)
    sock = bind("127.0.0.1", 0)
    server = make_server(studio)
    thread = threading.Thread(target=server.run, kwargs={"sockets": [sock]}, daemon=True)
    thread.start()
    deadline = time.monotonic() + 20
    while not server.started:
        if time.monotonic() > deadline or not thread.is_alive():
            pytest.fail("the studio server did not start")
        time.sleep(0.02)
    try:
        yield Served(studio, url_of(sock, studio.token), spec, server)
    finally:
        server.should_exit = True
        thread.join(10)
        sock.close()


serving = contextmanager(serve)
