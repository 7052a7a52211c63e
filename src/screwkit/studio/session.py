"""One tab of the studio: the messages a page may send (validated with pydantic, anything else
is answered with an error), the tab's design state with its undo and redo history, and the
answers (docs/studio.md, "Messages").

A page sends JSON objects with a ``type``:

``{"type": "set", "seq": n, "values": {"dimensions.d2": 4.6}, "mode": 1}``
    Change values (in the units the page shows) and/or the assembly mode; the answer is a
    ``state``. Values and mode that are left out keep theirs.
``{"type": "undo" | "redo" | "state", "seq": n}``
    Step back or forward through the tab's history, or ask for the current state.
``{"type": "numbers", "seq": n}``
    The table of the CLI's numbers (limit positions, minimum transmission) of the current
    state: slower than the curves, so a page asks for it once they are drawn.
``{"type": "save", "seq": n}``
    Write the tab's design into the spec file the studio was started with.
``{"type": "export", "seq": n, "what": "report" | "csv" | "spec"}``
    The HTML report, the CSV of the curves or the spec under a new name: a ``download`` the
    page saves, and for ``spec`` the file given with ``--save-as`` when there is one.

Answers: ``{"type": "state", "seq", "values", "mode", "can_undo", "can_redo", "result"}``
(``result`` is :func:`~screwkit.studio.solve.solve_spec`'s dictionary without the scene and
the numbers, or ``{"ok": false, "error": sentence}`` where the design cannot be solved),
followed, when solved, by ``{"type": "scene", "seq", "scene"}`` (the 3-D view's scene) and,
for a warm-started joint list (``result["warm"]``), by ``{"type": "checked", "seq"}`` once
:meth:`Tab.verify` confirms it or by the state solved anew and its scene;
``{"type": "saved", "seq", "path"}``,
``{"type": "numbers", "seq", "numbers"}``, ``{"type": "download", "seq", "name", "mime", "text"}`` and ``{"type": "error", "seq",
"message"}``. No message carries a file path to the server.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, TypeAdapter, ValidationError

from screwkit.errors import ScrewkitError
from screwkit.kinematics.motion import AssemblyError
from screwkit.pipeline import Pipeline
from screwkit.studio.design import Design

#: how many steps back a tab remembers
HISTORY = 200
#: the longest message a page may send (characters)
MAX_MESSAGE = 100_000


class _Message(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=True)
    seq: int = Field(0, ge=0, le=2**53)


class SetMessage(_Message):
    type: Literal["set"]
    values: dict[Annotated[str, Field(max_length=200)], float] = Field(
        default_factory=dict, max_length=1000)
    mode: int | None = Field(None, ge=0, le=7)


class StepMessage(_Message):
    type: Literal["undo", "redo", "state", "save", "numbers"]


class ExportMessage(_Message):
    type: Literal["export"]
    what: Literal["report", "csv", "spec"]


Message = Annotated[SetMessage | StepMessage | ExportMessage, Field(discriminator="type")]
MESSAGE = TypeAdapter(Message)


def parse_message(text: str) -> SetMessage | StepMessage | ExportMessage:
    """A page's message, validated; a :class:`~screwkit.studio.design.StudioError` naming
    what is wrong otherwise."""
    from screwkit.studio.design import StudioError

    if len(text) > MAX_MESSAGE:
        raise StudioError(f"message of {len(text)} characters; the limit is {MAX_MESSAGE}")
    try:
        data = json.loads(text)
    except (json.JSONDecodeError, RecursionError) as exc:
        raise StudioError(f"the message is not JSON ({exc})") from None
    try:
        return MESSAGE.validate_python(data)
    except ValidationError as exc:
        first = exc.errors()[0]
        where = ".".join(str(p) for p in first["loc"]) or "message"
        raise StudioError(f"bad message at {where}: {first['msg']}") from None


@dataclass(frozen=True)
class DesignState:
    values: tuple[tuple[str, float], ...]
    mode: int

    @property
    def as_dict(self) -> dict[str, float]:
        return dict(self.values)


@dataclass
class Tab:
    """One page's design and history (module docstring). ``save_as``: the file given on the
    command line for *export spec* (None: a download only)."""

    design: Design
    save_as: Path | None = None
    history: list[DesignState] = field(default_factory=list)
    future: list[DesignState] = field(default_factory=list)
    #: the JSON of each part of the last solved state sent to the page (the server leaves out
    #: the parts that have not changed since: studio/server.py, state_json)
    sent: dict[tuple[Any, ...], bytes] = field(default_factory=dict)

    def __post_init__(self) -> None:
        d = self.design
        self.state = DesignState(tuple(d.initial_values.items()), d.initial_mode)
        self._solved: tuple[DesignState, Any] | None = None
        self._unchecked = False  # the solved state's motion is a warm start not yet confirmed

    def set(self, values: dict[str, float], mode: int | None) -> None:
        merged = {**self.state.as_dict, **values}
        new = DesignState(tuple(merged.items()),
                          self.state.mode if mode is None else mode)
        self.design.check(new.as_dict, new.mode)
        if new != self.state:
            self.history = [*self.history, self.state][-HISTORY:]
            self.future = []
            self.state = new

    def step(self, back: bool) -> None:
        source, target = (self.history, self.future) if back else (self.future, self.history)
        if source:
            target.append(self.state)
            self.state = source.pop()

    def pipeline(self, checked: bool = True) -> Any:
        """The pipeline of the current state (solved once per state); for a graph spec a
        :class:`~screwkit.studio.graph.GraphRun`. A joint list solved by the generic solver
        is warm-started from the state before (:meth:`_warm`); ``checked``: first confirm a
        warm start by the generic solver's own root search (:meth:`verify`)."""
        if self._solved is None or self._solved[0] != self.state:
            spec = self.design.spec_with(self.state.as_dict, self.state.mode)
            if self.design.graph:
                from screwkit.studio.graph import GraphRun

                self._solved = (self.state, GraphRun(spec, self.state.mode))
            else:
                pipe = Pipeline(spec)
                self._unchecked = self._warm(pipe)
                self._solved = (self.state, pipe)
        if checked:
            self.verify()
        return self._solved[1]

    def _warm(self, pipe: Pipeline) -> bool:
        """Give ``pipe`` the motion warm-started from the last solved state's
        (:func:`~screwkit.kinematics.warm_motion.warm_motion`: batched Newton on every sample
        of every mode, checked for closure, continuity and distinct modes); True if it did.
        Anything else (a closed form, a mode that does not assemble everywhere, a change too
        large for Newton) is solved anew when the motion is first asked for. A change of the
        mode alone keeps the motion (every mode is solved; the mode picks the loads)."""
        from screwkit.kinematics.warm_motion import warm_motion

        before = None if self._solved is None else self._solved[1]
        motion = None if before is None else before.__dict__.get("motion")
        if motion is None:
            return False
        assert self._solved is not None
        if self._solved[0].values == self.state.values:  # only the mode changed: the same loop
            pipe.motion = motion
            return self._unchecked
        spec = pipe.spec
        try:
            warm = warm_motion(spec.linkage, spec.inputs, motion, rates=spec.speed,
                               accelerations=spec.acceleration)
        except (ScrewkitError, FloatingPointError, np.linalg.LinAlgError):
            warm = None
        if warm is None:
            return False
        pipe.motion = warm  # the cached property's value (Pipeline.motion)
        return True

    @property
    def warm(self) -> bool:
        """Whether the current state's motion is a warm start not yet confirmed."""
        return self._unchecked and self._solved is not None and self._solved[0] == self.state

    def verify(self) -> bool | None:
        """Confirm a warm-started motion (:func:`~screwkit.kinematics.warm_motion.
        same_modes_as_search`: the generic solver's first root search finds exactly its
        modes) or, where it does not, solve the state anew. None: nothing to confirm; False:
        confirmed; True: replaced by the generic solver's motion (the page's answer changes)."""
        if not self.warm:
            return None
        from screwkit.kinematics.warm_motion import same_modes_as_search

        self._unchecked = False
        assert self._solved is not None
        if same_modes_as_search(self._solved[1].motion):
            return False
        self._solved = (self.state, Pipeline(self._solved[1].spec))
        return True

    def solved(self, *, numbers: bool, scene: bool) -> dict[str, Any]:
        """The page's picture of the current state (studio/solve.py, studio/graph.py)."""
        if self.design.graph:
            from screwkit.studio.graph import solve_graph

            return solve_graph(self.pipeline(), numbers=numbers, scene=scene)
        from screwkit.studio.solve import solve_spec

        return {**solve_spec(self.pipeline(checked=False), numbers=numbers, scene=scene),
                "warm": self.warm}

    def answer(self, seq: int) -> dict[str, Any]:
        """The ``state`` answer: the values, the history flags and the solved design (without
        the numbers table, which a ``numbers`` message asks for)."""
        values, mode = self.state.as_dict, self.state.mode
        try:
            result = self.solved(numbers=False, scene=False)
        except AssemblyError as exc:
            result = {"ok": False, "error": str(exc), "where": self.where_it_closes()}
        except ScrewkitError as exc:
            result = {"ok": False, "error": str(exc)}
        except (FloatingPointError, np.linalg.LinAlgError) as exc:
            result = {"ok": False, "error": f"the solver failed numerically at these values "
                                            f"({exc}); change a dimension"}
        return {"type": "state", "seq": seq, "values": values, "mode": mode,
                "can_undo": bool(self.history), "can_redo": bool(self.future),
                "result": result}

    def where_it_closes(self) -> str | None:
        """For a state where the loop closes nowhere: the values of the dimension changed
        last at which it closes (:func:`~screwkit.studio.solve.assembling_values`)."""
        from screwkit.studio.solve import assembling_values

        if not self.history:
            return None
        before, now = self.history[-1].as_dict, self.state.as_dict
        changed = [k for k in now if now[k] != before.get(k)]
        if len(changed) != 1:
            return None
        return assembling_values(self.design, now, self.state.mode, changed[0])

    def scene(self, seq: int) -> dict[str, Any]:
        """The ``scene`` message: the 3-D scene of the current state (sent after its
        ``state``)."""
        if self.design.graph:
            from screwkit.studio.graph import graph_scene

            run = self.pipeline()
            return {"type": "scene", "seq": seq, "scene": graph_scene(run, run.dynamics()[0])}
        from screwkit.studio.solve import packed_scene

        return {"type": "scene", "seq": seq, "scene": packed_scene(self.pipeline(checked=False))}

    def with_scene(self, answer: dict[str, Any]) -> dict[str, Any]:
        """A solved ``state`` answer with the 3-D scene of its state under ``"scene"``: one
        message, so that the page draws the curves and hands the view its new frames in one
        task and one frame (docs/studio.md, "Speed")."""
        return {**answer, "scene": self.scene(answer["seq"])["scene"]}

    def handle(self, text: str) -> dict[str, Any]:
        """The answer to one message from the page (never raises for a page's mistake)."""
        seq = 0
        try:
            msg = parse_message(text)
            seq = msg.seq
            if isinstance(msg, SetMessage):
                self.set(msg.values, msg.mode)
            elif isinstance(msg, ExportMessage):
                return self.export(msg.what, seq)
            elif msg.type in ("undo", "redo"):
                self.step(msg.type == "undo")
            elif msg.type == "numbers":
                return {"type": "numbers", "seq": seq, "numbers": self.numbers()}
            elif msg.type == "save":
                path = save_design(self.design, self.state.as_dict, self.state.mode)
                return {"type": "saved", "seq": seq, "path": str(path)}
            return self.answer(seq)
        except ScrewkitError as exc:
            return {"type": "error", "seq": seq, "message": str(exc)}

    def numbers_job(self, text: str) -> Callable[[], dict[str, Any] | None] | None:
        """For a ``numbers`` message: a job that answers it from the current state's pipeline
        (taken now), which the server runs beside the messages that follow (the table takes
        up to a few hundred ms; a change sent meanwhile is not kept waiting); the job answers
        None when a later change has made the table stale. None for any other message (and
        for a malformed one, which :meth:`handle` answers)."""
        try:
            msg = parse_message(text)
        except ScrewkitError:
            return None
        if not (isinstance(msg, StepMessage) and msg.type == "numbers"):
            return None
        state, seq = self.state, msg.seq
        try:
            pipe = self.pipeline()
        except ScrewkitError as exc:
            failed = {"type": "error", "seq": seq, "message": str(exc)}
            return lambda: failed

        def job() -> dict[str, Any] | None:
            if self.state != state:
                return None
            try:
                return {"type": "numbers", "seq": seq, "numbers": self._numbers_of(pipe)}
            except ScrewkitError as exc:
                return {"type": "error", "seq": seq, "message": str(exc)}

        return job

    def _numbers_of(self, pipe: Any) -> list[list[str]]:
        if self.design.graph:
            from screwkit.studio.graph import graph_numbers

            return graph_numbers(pipe)
        from screwkit.studio.solve import numbers_table

        return numbers_table(pipe)

    def numbers(self) -> list[list[str]]:
        """The numbers table of the current state."""
        if self.design.graph:
            from screwkit.studio.graph import graph_numbers

            return graph_numbers(self.pipeline())
        from screwkit.studio.solve import numbers_table

        return numbers_table(self.pipeline())

    def export(self, what: str, seq: int) -> dict[str, Any]:
        from screwkit.studio.exports import export_csv, export_report

        values, mode = self.state.as_dict, self.state.mode
        stem = self.design.path.stem
        if what == "spec":
            text = self.design.text_with(values, mode)
            if self.save_as is not None:
                write_spec(self.save_as, text, self.design)
                return {"type": "saved", "seq": seq, "path": str(self.save_as)}
            return {"type": "download", "seq": seq, "name": f"{stem}_studio.toml",
                    "mime": "application/toml", "text": text}
        spec = self.design.spec_with(values, mode)
        if self.design.graph:
            from screwkit.studio.graph import GraphRun, graph_csv, graph_report

            if what == "csv":
                return {"type": "download", "seq": seq, "name": f"{stem}_studio.csv",
                        "mime": "text/csv", "text": graph_csv(GraphRun(spec, mode))}
            return {"type": "download", "seq": seq, "name": f"{stem}_studio.html",
                    "mime": "text/html",
                    "text": graph_report(spec, self.design.text_with(values, mode))}
        if what == "csv":
            return {"type": "download", "seq": seq, "name": f"{stem}_studio.csv",
                    "mime": "text/csv", "text": export_csv(spec)}
        return {"type": "download", "seq": seq, "name": f"{stem}_studio.html",
                "mime": "text/html", "text": export_report(spec, self.design.text_with(values, mode))}


def write_spec(path: Path, text: str, design: Design) -> None:
    """Write a spec file's text atomically after checking it loads as the design's spec does
    (a file that would not load is never written)."""
    import tomlkit

    from screwkit.io.results import write_atomic

    design.load_tables(tomlkit.parse(text).unwrap())
    write_atomic(path, text)


def save_design(design: Design, values: dict[str, float], mode: int) -> Path:
    """Write the design into the spec file it was read from: the old file is first copied to
    ``<name>.toml.bak``, then the new text replaces it atomically (docs/studio.md, "Save")."""
    from screwkit.io.results import write_atomic

    text = design.text_with(values, mode)
    path = design.path
    write_atomic(path.with_name(path.name + ".bak"), path.read_text(encoding="utf-8"))
    write_spec(path, text, design)
    return path
