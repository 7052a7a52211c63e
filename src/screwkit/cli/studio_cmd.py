"""``screwkit studio SPEC``: a local web app where the spec's dimensions are dragged and the
mechanism, its curves and its loads are solved again at once (docs/studio.md). It prints the
URL (with its per-session token), opens the browser unless ``--no-browser``, and serves until
Ctrl-C. Registered on the main app by ``register(app)``; the app is :mod:`screwkit.studio`."""

from __future__ import annotations

import socket
from pathlib import Path
from typing import Annotated

import typer

from screwkit.errors import InputError


def _need_extra() -> None:
    try:
        import starlette  # noqa: F401
        import tomlkit  # noqa: F401
        import uvicorn  # noqa: F401
        import websockets  # noqa: F401
    except ImportError as exc:
        raise InputError(f"`screwkit studio` needs the studio extra ({exc.name} is missing): "
                         "pip install 'screwkit[studio]'") from None


def _listen(host: str, port: int) -> socket.socket:
    from screwkit.studio.server import bind

    try:
        return bind(host, port)
    except OSError as exc:
        raise InputError(f"cannot listen on {host}:{port} ({exc.strerror or exc}); give "
                         "another --port (0 picks a free one) or --host") from None


def register(app: typer.Typer) -> None:
    """Add the ``studio`` command to ``app``."""

    @app.command()
    def studio(
        spec: Annotated[Path, typer.Argument(help="Spec file (TOML); Save writes the new values back into it (the old file is kept as <spec>.bak).")],
        host: Annotated[str, typer.Option("--host", help="Address to listen on (default: this computer only).")] = "127.0.0.1",
        port: Annotated[int, typer.Option("--port", help="Port to listen on (0: a free port).", min=0, max=65535)] = 0,
        no_browser: Annotated[bool, typer.Option("--no-browser", help="Print the URL only; do not open a browser.")] = False,
        save_as: Annotated[Path | None, typer.Option("--save-as", help="The file 'export spec' writes (a new name); without it the page downloads the spec instead.")] = None,
    ) -> None:
        """Design by hand in the browser: drag a dimension, see the mechanism, its curves and loads change at once (Ctrl-C stops)."""
        import webbrowser

        from screwkit.cli.common import check_paths, console, guard

        guard(_need_extra)
        from screwkit.studio.server import make_server, new_studio, url_of

        if save_as is not None:
            check_paths([spec], {"--save-as": save_as})
        studio_app = guard(lambda: new_studio(spec, save_as))
        sock = guard(lambda: _listen(host, port))
        url = url_of(sock, studio_app.token)
        console.print(f"screwkit studio of {spec} at\n  {url}\n(Ctrl-C stops it)",
                      highlight=False, soft_wrap=True)
        if not no_browser:
            webbrowser.open(url)
        server = make_server(studio_app)
        try:
            server.run(sockets=[sock])
        except KeyboardInterrupt:
            pass
        finally:
            sock.close()
        console.print("studio stopped", highlight=False)
