"""The studio's local web server: one Starlette app on uvicorn serving the page, its three
static files and one WebSocket per tab (docs/studio.md).

Security (as Jupyter does it): every request must carry the per-session token in its URL
(``?token=…``), compared in constant time; a request without it gets HTTP 403 and a WebSocket
without it is refused before the handshake completes. A WebSocket whose ``Origin`` is not the
server's own host is refused too. The server binds 127.0.0.1 unless ``--host`` says otherwise,
never reads a file path from a page, and writes only the spec it was started with (Save) or the
``--save-as`` file (export spec); both atomically, so Ctrl-C leaves no half-written file.
"""

from __future__ import annotations

import contextlib
import json
import logging
import math
import secrets
import socket
import threading
from collections.abc import Callable
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any
from urllib.parse import urlsplit

from screwkit.studio.design import Design
from screwkit.studio.session import Tab

log = logging.getLogger("screwkit.studio")

#: the static files a page may ask for, by name → (package folder, file, media type)
STATIC = {
    "viewer.js": ("screwkit.report", "screwkit-viewer.min.js", "text/javascript"),
    "studio.js": ("screwkit.studio", "studio.js", "text/javascript"),
    "studio.css": ("screwkit.studio", "studio.css", "text/css"),
}


def finite(doc: Any) -> Any:
    """A copy of a JSON-able document with every NaN or infinite float as ``None`` (JSON has
    no NaN)."""
    if isinstance(doc, float):
        return doc if math.isfinite(doc) else None
    if isinstance(doc, dict):
        return {k: finite(v) for k, v in doc.items()}
    if isinstance(doc, list | tuple):
        return [finite(v) for v in doc]
    return doc


def to_json(doc: Any) -> str:
    """The document as compact JSON, a NaN or infinity as ``null`` (orjson, which writes every
    float as Python's shortest round-trip repr does and a NaN or infinity as ``null``, several
    times faster than :mod:`json` on the answers' long series; :func:`finite` and :mod:`json`
    for a document orjson does not take)."""
    import orjson

    try:
        return orjson.dumps(doc, option=orjson.OPT_SERIALIZE_NUMPY).decode()
    except (orjson.JSONEncodeError, TypeError):
        return json.dumps(finite(doc), separators=(",", ":"))


#: a part of a state shorter than this (JSON characters) is always sent
SMALL_PART = 256


def _parts(reply: dict[str, Any]) -> list[tuple[Any, ...]]:
    """The paths of the parts of a solved state that are compared with the ones sent before:
    each entry of its ``result``, each entry of its ``scene`` but the modes, and each entry
    of each of the scene's modes (so that a change of the mode alone, which moves the load
    arrows from one mode to another, resends the arrows and not the mode's frames)."""
    paths: list[tuple[Any, ...]] = [("result", k) for k in reply["result"]]
    scene = reply.get("scene")
    if isinstance(scene, dict):
        paths += [("scene", k) for k in scene if k != "modes"]
        for i, mode in enumerate(scene.get("modes") or []):
            paths += [("scene", "modes", i, k) for k in mode]
    return paths


def state_json(reply: dict[str, Any], sent: dict[tuple[Any, ...], bytes]) -> str:
    """A ``state`` answer as JSON without the parts the page already holds: each part
    (:func:`_parts`) whose JSON is the one sent last on this WebSocket (``sent``, updated) is
    left out and its path listed in ``"unchanged"``; the page takes those from the state
    and scene it holds (docs/studio.md, "Messages"). A state that is not solved is sent
    whole and forgets what was sent (the page then holds no solved state)."""
    import orjson

    result = reply.get("result") or {}
    if reply.get("type") != "state" or not result.get("ok"):
        sent.clear()
        return to_json({**reply, "unchanged": []} if reply.get("type") == "state" else reply)
    doc: dict[str, Any] = {**reply, "result": dict(result)}
    if isinstance(reply.get("scene"), dict):
        doc["scene"] = {**reply["scene"], "modes": [dict(m) for m in reply["scene"]["modes"]]}
    unchanged: list[list[Any]] = []
    scene_moved = False
    paths = _parts(reply)
    for gone in set(sent) - set(paths):  # what the page's state no longer holds
        del sent[gone]
    for path in paths:
        holder: Any = doc
        for key in path[:-1]:
            holder = holder[key]
        text = to_json(holder[path[-1]]).encode()
        if sent.get(path) != text:
            scene_moved |= path[0] == "scene"
            sent[path] = text
            holder[path[-1]] = orjson.Fragment(text)
        elif len(text) >= SMALL_PART:
            del holder[path[-1]]
            unchanged.append(list(path))
        else:
            holder[path[-1]] = orjson.Fragment(text)
    if "scene" in doc and not scene_moved:
        del doc["scene"]  # the view shows this scene already
        unchanged = [p for p in unchanged if p[0] != "scene"] + [["scene"]]
    doc["unchanged"] = unchanged
    return orjson.dumps(doc).decode()


@dataclass
class Studio:
    """What one studio process serves: the design, its token and the ``--save-as`` file."""

    design: Design
    token: str
    save_as: Path | None = None

    def allowed(self, token: str | None) -> bool:
        return token is not None and secrets.compare_digest(token.encode(), self.token.encode())


def _static(name: str) -> tuple[bytes, str]:
    package, file, media = STATIC[name]
    folder = "static"
    return (resources.files(package) / folder / file).read_bytes(), media


def create_app(studio: Studio) -> Any:
    """The Starlette application of a studio."""
    from starlette.applications import Starlette
    from starlette.requests import Request
    from starlette.responses import HTMLResponse, PlainTextResponse, Response
    from starlette.routing import Route, WebSocketRoute
    from starlette.websockets import WebSocket, WebSocketDisconnect

    from screwkit.studio.page import render_page

    refused = "this studio needs its token: open the URL `screwkit studio` printed"

    async def page(request: Request) -> Response:
        if not studio.allowed(request.query_params.get("token")):
            return PlainTextResponse(refused, status_code=403)
        html = render_page(studio.design, studio.token)
        return HTMLResponse(html, headers={"Cache-Control": "no-store",
                                           "X-Content-Type-Options": "nosniff",
                                           "Referrer-Policy": "no-referrer"})

    async def static(request: Request) -> Response:
        name = request.path_params["name"]
        if not studio.allowed(request.query_params.get("token")):
            return PlainTextResponse(refused, status_code=403)
        if name not in STATIC:
            return PlainTextResponse("not found", status_code=404)
        body, media = _static(name)
        return Response(body, media_type=media,
                        headers={"Cache-Control": "private, max-age=3600"})

    save_lock = threading.Lock()

    def guarded(answer: Callable[[], dict[str, Any]]) -> dict[str, Any]:
        with save_lock:  # one file write at a time; solving is quick
            try:
                return answer()
            except Exception as exc:  # a bug, not the page's mistake: say so, keep serving
                log.exception("studio: the answer to a message failed")
                return {"type": "error", "seq": 0, "message": f"internal error ({exc!r}); "
                        "the studio goes on — please report this with the spec"}

    def handle(tab: Tab, text: str) -> tuple[str, int | None]:
        """The answer to ``text`` as JSON — a solved state with its 3-D scene in the same
        message (Tab.with_scene) — and the seq of a solved state or None."""
        reply = guarded(lambda: tab.handle(text))
        solved = reply["type"] == "state" and bool(reply["result"].get("ok"))
        if solved:
            reply = guarded(lambda: tab.with_scene(reply))
        if reply["type"] != "state":
            return to_json(reply), None
        return state_json(reply, tab.sent), reply["seq"] if solved else None

    def check(tab: Tab, seq: int) -> list[str]:
        """After a warm-started answer and its scene: confirm it (``checked``) or, where the
        generic solver's root search finds other modes, the answer of the state solved anew
        and its scene (Tab.verify)."""
        outcome = guarded(lambda: {"type": "verify", "seq": seq, "replaced": tab.verify()})
        if outcome["type"] != "verify" or outcome["replaced"] is None:
            return [] if outcome["type"] == "verify" else [to_json(outcome)]
        if not outcome["replaced"]:
            return [to_json({"type": "checked", "seq": seq})]
        return [handle(tab, json.dumps({"type": "state", "seq": seq}))[0]]

    async def updates(ws: WebSocket) -> None:
        origin = ws.headers.get("origin")
        host = ws.headers.get("host", "")
        if not studio.allowed(ws.query_params.get("token")) or (
                origin is not None and urlsplit(origin).netloc != host):
            await ws.close(code=1008)
            return
        await ws.accept()
        try:
            await serve_tab(ws, Tab(studio.design, studio.save_as), handle, check)
        except WebSocketDisconnect:  # the tab was closed while an answer was on its way
            return

    return Starlette(routes=[Route("/", page), Route("/static/{name}", static),
                             WebSocketRoute("/ws", updates)])


async def serve_tab(ws: Any, tab: Tab, handle: Callable[[Tab, str], tuple[str, int | None]],
                    check: Callable[[Tab, int], list[str]]) -> None:
    """One tab's WebSocket: each message answered in turn (``handle``; a solved state, which
    carries its 3-D scene, is followed by a warm start's ``check``), except a numbers table,
    computed beside the messages that follow (Tab.numbers_job)."""
    import anyio
    from starlette.websockets import WebSocketDisconnect

    sending = anyio.Lock()

    async def send(text: str) -> None:
        async with sending:
            await ws.send_text(text)

    async def numbers(job: Callable[[], dict[str, Any] | None]) -> None:
        def run() -> str | None:
            try:
                reply = job()
            except Exception as exc:  # a bug: say so, keep serving
                log.exception("studio: the numbers table failed")
                reply = {"type": "error", "seq": 0, "message": f"internal error ({exc!r})"}
            return None if reply is None else to_json(reply)

        answer = await anyio.to_thread.run_sync(run)
        if answer is not None:
            with contextlib.suppress(Exception):  # the tab may have closed meanwhile
                await send(answer)

    async def read(inbox: Any) -> None:
        """Every message of the tab into ``inbox``, so that the loop below can see whether
        another is waiting."""
        async with inbox:
            while True:
                try:
                    message = await ws.receive()
                except Exception:  # the connection is gone (a disconnect already read)
                    message = {"type": "websocket.disconnect", "code": 1006}
                await inbox.send(message)
                if message["type"] == "websocket.disconnect":
                    return

    def waiting(outbox: Any) -> dict[str, Any] | None:
        try:
            return dict(outbox.receive_nowait())
        except (anyio.WouldBlock, anyio.EndOfStream):
            return None

    text: str | None = '{"type": "state", "seq": 0}'
    inbox, outbox = anyio.create_memory_object_stream[dict[str, Any]](math.inf)
    async with anyio.create_task_group() as tasks, outbox:
        tasks.start_soon(read, inbox)
        try:
            while True:
                message: dict[str, Any] | None = None
                if text is not None:
                    job = await anyio.to_thread.run_sync(tab.numbers_job, text)
                    if job is not None:
                        tasks.start_soon(numbers, job)
                    else:
                        answer, solved = await anyio.to_thread.run_sync(handle, tab, text)
                        await send(answer)
                        if solved is not None:
                            # a warm start's check, unless the page has sent another message
                            # meanwhile (a drag): that state is then past, and whatever comes
                            # next is checked on its own (Tab.pipeline, Tab.verify)
                            message = waiting(outbox)
                            if message is None:
                                for follow in await anyio.to_thread.run_sync(check, tab, solved):
                                    await send(follow)
                if message is None:
                    message = dict(await outbox.receive())
                if message["type"] == "websocket.disconnect":
                    return
                text = message.get("text")
                if text is None:
                    await send(json.dumps({"type": "error", "seq": 0, "message":
                                           "send JSON text messages, not binary"}))
        except (WebSocketDisconnect, anyio.EndOfStream):  # the tab closed meanwhile
            return
        finally:
            tasks.cancel_scope.cancel()

def bind(host: str, port: int) -> socket.socket:
    """A listening socket on ``host:port`` (port 0: a free port chosen by the system)."""
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    sock = socket.socket(family, socket.SOCK_STREAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    sock.bind((host, port))
    sock.listen(128)
    sock.set_inheritable(True)
    return sock


def url_of(sock: socket.socket, token: str) -> str:
    host, port = sock.getsockname()[:2]
    shown = f"[{host}]" if ":" in host else host
    return f"http://{shown}:{port}/?token={token}"


def make_server(studio: Studio) -> Any:
    """A uvicorn server of the studio's app (quiet; ``serve(sockets=[bind(...)])`` runs it)."""
    import uvicorn

    config = uvicorn.Config(create_app(studio), log_level="warning", ws="websockets-sansio",
                            lifespan="off", ws_max_size=1 << 20)
    return uvicorn.Server(config)


def new_studio(spec: str | Path, save_as: Path | None = None) -> Studio:
    """A studio of the spec file ``spec`` with a fresh random token."""
    return Studio(Design(spec), secrets.token_urlsafe(24), save_as)
