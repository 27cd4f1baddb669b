"""Run one chapter on a reader's program: ``make chapter NB=<notebook> PROGRAM=<file>``.

``python -m nctwin.report.chapter NOTEBOOK [--program FILE] [-p NAME VALUE ...] [--out DIR]``
executes the notebook with papermill (``program`` set to FILE made absolute, and each ``-p``:
True, False, None or a number where VALUE reads as one, else a string), headless, in the
repository root, and writes the executed notebook and its HTML to ``DIR/<stem>.ipynb`` and
``DIR/<stem>.html`` (default ``build/chapter/``). The chapter's tables and claims go to
``DIR/<stem>/results/`` (through ``NCTWIN_RESULTS``): ``results/``, ``book/notebooks/`` and the
committed notebooks are never touched. The networks come from the chapter's cache in
``data/cache/`` (a chapter that has not run before trains them first).

A notebook or program that does not exist, a parameter the chapter does not take, or a value of
another kind than its default is named in one line before anything runs (exit 2). An input the
chapter's method cannot run is named in one line after the chapter ran (exit 2: its last section
says ``not run: <reason>``). A chapter that fails names its partly executed notebook (exit 1).
"""

from __future__ import annotations

import argparse
import ast
import os
import sys
import warnings
from pathlib import Path

from .. import paths

__all__ = ["check_parameters", "execute", "main", "refused", "resolve_notebook", "write_html"]

#: The kernel's figures: inline (the Makefile's notebooks use the same backend).
NB_MPLBACKEND = "module://matplotlib_inline.backend_inline"
#: Where a chapter run on a reader's program writes, under the repository root.
OUT_DIR = Path("build") / "chapter"


def resolve_notebook(name: str, root: Path) -> Path:
    """The chapter notebook ``name`` names: a path, or a stem of ``notebooks/`` (with or
    without ``.ipynb``).

    Raises
    ------
    ValueError
        If no such notebook exists; the message lists the chapters.
    """
    for candidate in (Path(name), root / "notebooks" / Path(name).with_suffix(".ipynb").name):
        if candidate.is_file() and candidate.suffix == ".ipynb":
            return candidate.resolve()
    stems = ", ".join(sorted(p.stem for p in (root / "notebooks").glob("*.ipynb")))
    raise ValueError(f"NB={name}: no such notebook; the chapters are {stems}")


def execute(notebook: Path, out_dir: Path, parameters: dict, root: Path) -> Path:
    """Execute ``notebook`` with papermill into ``out_dir`` and write its HTML beside it.

    Returns
    -------
    pathlib.Path
        The HTML file.
    """
    import papermill
    from traitlets.config import Config

    out_dir.mkdir(parents=True, exist_ok=True)
    executed = out_dir / notebook.name
    env = {"NCTWIN_RESULTS": str(out_dir / notebook.stem / "results"),
           "MPLBACKEND": NB_MPLBACKEND,
           "TQDM_DISABLE": "1"}  # fmt: skip
    before = {k: os.environ.get(k) for k in env}
    os.environ.update(env)  # the kernel inherits them
    try:
        papermill.execute_notebook(
            str(notebook), str(executed), parameters=parameters, cwd=str(root),
            kernel_name="python3", progress_bar=False,
            config=Config(KernelManager={"transport": "ipc"}),
            extra_arguments=["--InteractiveShell.colors=nocolor"],
        )  # fmt: skip
    finally:
        for k, v in before.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v
    return write_html(executed)


def write_html(executed: Path) -> Path:
    """The executed notebook as HTML beside it (``<stem>.html``), which it returns."""
    import nbformat
    from nbconvert import HTMLExporter

    with warnings.catch_warnings():  # glue's records (display=False) have no HTML form
        warnings.filterwarnings("ignore", "Your element with mimetype", UserWarning)
        body, _ = HTMLExporter().from_notebook_node(nbformat.read(executed, as_version=4))
    html = executed.with_suffix(".html")
    html.write_text(body, encoding="utf-8")
    return html


def check_parameters(notebook: Path, parameters: dict) -> None:
    """Refuse, before anything runs, a parameter the chapter's parameters cell does not set, or a
    value of another kind than the cell's default (a whole number where it is one, a number where
    it is a float, True or False where it is either; any value where it is None).

    Raises
    ------
    ValueError
        Naming the first parameter refused, its value and what the chapter takes.
    """
    import papermill

    known = papermill.inspect_notebook(str(notebook))
    for name, value in parameters.items():
        flag = "PROGRAM" if name == "program" else f"-p {name}"
        if name not in known:
            allowed = f"its parameters are {', '.join(known)}" if known else "it has none"
            raise ValueError(f"{flag} = {value!r}: {notebook.stem} takes no such parameter; "
                             f"{allowed}")  # fmt: skip
        default = _literal(known[name]["default"])
        if not _fits(default, value):
            raise ValueError(f"{flag} = {value!r}: {notebook.stem} takes "
                             f"{_KIND_NAMES[type(default)]} (default {default!r})")  # fmt: skip


#: What a parameter of each default's type takes, in words.
_KIND_NAMES = {bool: "True or False", int: "a whole number", float: "a number"}


def _literal(source: str) -> object:
    """A parameter's default as Python reads it; None (any value) where it is an expression."""
    try:
        return ast.literal_eval(source)
    except (ValueError, SyntaxError):
        return None


def _fits(default: object, value: object) -> bool:
    """Whether ``value`` is of the kind of the parameter's ``default`` (None takes anything)."""
    if isinstance(default, bool) or isinstance(value, bool):
        return default is None or type(value) is type(default)
    if isinstance(default, int):
        return isinstance(value, int)
    if isinstance(default, float):
        return isinstance(value, int | float)
    return True


def _value(text: str) -> bool | int | float | str | None:
    """A ``-p`` value as the notebook reads it: True, False, None, a number, else the text."""
    if text in ("True", "False", "None"):
        return ast.literal_eval(text)
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text


def main(argv: list[str] | None = None) -> int:
    """The command line; see the module's docstring."""
    parser = argparse.ArgumentParser(prog="python -m nctwin.report.chapter")
    parser.add_argument("notebook", help="a chapter: a notebook path or a stem of notebooks/")
    parser.add_argument("--program", help="a G-code file the chapter runs its method on")
    parser.add_argument(
        "-p",
        "--parameter",
        nargs=2,
        action="append",
        default=[],
        metavar=("NAME", "VALUE"),
        help="another parameter of the chapter",
    )
    parser.add_argument("--out", help=f"output folder (default {OUT_DIR}/ in the repository)")
    args = parser.parse_args(argv)
    root = paths.repo_root()
    try:
        notebook = resolve_notebook(args.notebook, root)
        parameters = {name: _value(v) for name, v in args.parameter}
        if args.program:
            program = Path(args.program).resolve()
            if not program.is_file():
                raise ValueError(f"PROGRAM={args.program}: no such file")
            parameters["program"] = str(program)
        check_parameters(notebook, parameters)
    except ValueError as exc:
        print(f"chapter: {exc}", file=sys.stderr)
        return 2
    out_dir = Path(args.out).resolve() if args.out else root / OUT_DIR
    from papermill.exceptions import PapermillExecutionError

    try:
        html = execute(notebook, out_dir, parameters, root)
    except PapermillExecutionError as exc:
        print(f"chapter: {notebook.stem} failed in cell {exc.exec_count}: {exc.ename}: "
              f"{exc.evalue}; the partly executed notebook is {out_dir / notebook.name}",
              file=sys.stderr)  # fmt: skip
        return 1
    print(f"chapter: {out_dir / notebook.name}\nchapter: {html}")
    reasons = refused(out_dir / notebook.name)
    for reason in reasons:
        print(f"chapter: {notebook.stem}: {reason}", file=sys.stderr)
    return 2 if reasons else 0


def refused(executed: Path) -> list[str]:
    """The lines of ``not run: <reason>`` in the executed chapter's last cell (a reason may take
    one line per bad value): the section that runs the reader's input says so when the chapter's
    method cannot run it (the rest of the chapter ran)."""
    import nbformat

    last = nbformat.read(executed, as_version=4).cells[-1]
    texts = [o.get("text", "") for o in last.get("outputs", []) if o.get("output_type") == "stream"]
    return [line for t in texts if t.startswith("not run: ") for line in t.splitlines()]


if __name__ == "__main__":
    sys.exit(main())
