"""Click's own usage errors (an unknown option, a missing argument, a value of the wrong type)
printed like every other ``screwkit`` error (issue 30, the 80-column promise): click's usage line
and its "Try … --help" hint (click fits them to the width already), then ``error: <message>``
wrapped between words at the terminal width by :func:`screwkit.cli.common.print_error`, with
the continuation lines indented by two. The exit status is click's (2 for a usage error).

The command group :class:`ScrewkitGroup` catches them where click raises them — while it
parses its own options (``make_context``) and while it resolves and parses a subcommand
(``invoke``) — and hands typer an exception whose ``show`` prints them so.
"""

from __future__ import annotations

from typing import IO, Any

from typer.core import TyperGroup

from screwkit.errors import ScrewkitError

try:  # typer >= 0.20 runs on its own copy of click (typer._click), older typer on click
    from typer import _click as click  # type: ignore[attr-defined,unused-ignore]
    from typer._click.exceptions import NoArgsIsHelpError  # type: ignore[import-not-found,unused-ignore]
except ImportError:  # pragma: no cover - older typer
    import click  # type: ignore[no-redef,unused-ignore]
    from click.exceptions import NoArgsIsHelpError  # type: ignore[assignment,no-redef,unused-ignore]


class WrappedUsageError(click.ClickException, ScrewkitError):
    """A click error (``original``) that prints as a ``screwkit`` error: usage and hint, then
    the message wrapped at the terminal width; same exit status as ``original``. A user's
    mistake, so a :class:`~screwkit.errors.ScrewkitError` too."""

    def __init__(self, original: click.ClickException) -> None:
        super().__init__(original.format_message())
        self.original = original
        self.exit_code = original.exit_code

    def show(self, file: IO[Any] | None = None) -> None:
        from screwkit.cli.common import print_error

        ctx = getattr(self.original, "ctx", None)
        if ctx is not None:
            hint = ""
            if ctx.command.get_help_option(ctx) is not None:
                option = max(ctx.command.get_help_option_names(ctx), key=len)
                hint = f"Try '{ctx.command_path} {option}' for help.\n"
            click.echo(f"{ctx.get_usage()}\n{hint}", file=file, err=True, color=ctx.color)
        print_error(self.original.format_message())


def _wrapped(exc: click.ClickException) -> click.ClickException:
    """``exc`` ready to print as a screwkit error; "no arguments: print the help" as it is."""
    if isinstance(exc, NoArgsIsHelpError | WrappedUsageError):
        return exc
    return WrappedUsageError(exc)


class ScrewkitGroup(TyperGroup):
    """typer's command group whose usage errors print as :class:`WrappedUsageError`."""

    def make_context(self, info_name: str | None, args: list[str],
                     parent: click.Context | None = None, **extra: Any) -> click.Context:
        try:
            return super().make_context(info_name, args, parent, **extra)
        except click.ClickException as exc:
            raise _wrapped(exc) from exc

    def invoke(self, ctx: click.Context) -> Any:
        try:
            return super().invoke(ctx)
        except click.ClickException as exc:
            raise _wrapped(exc) from exc
