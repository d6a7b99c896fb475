"""Command-line plumbing shared by the CLIs (`tailsim.reports.compare`, `tailsim.campaign`,
`tailsim.reports.analysis`): every option is checked before any work starts, a bad value
ends the command with exit code 2 and one line on stderr naming the option, the value and
what is allowed; an unexpected error ends it with one line and exit code 1 (`--debug`:
the traceback).

Ranges of options that set a declared parameter come from `tailsim.declarations`."""

from __future__ import annotations

import argparse
import math
import pathlib
import sys
import zipfile
from collections.abc import Callable, Iterable, Sequence

from . import declarations

#: How to build the FMUs when a .fmu is missing or unreadable.
BUILD_HINT = "build them with `cargo xtask dist`"


class Parser(argparse.ArgumentParser):
    """An ArgumentParser whose errors are one line on stderr (`prog: error: ...`), exit code 2,
    with a `--debug` flag (traceback of an unexpected error)."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.add_argument("--debug", action="store_true", help="show the traceback of an unexpected error")

    def error(self, message: str):  # noqa: D102 - argparse's hook
        line = " ".join(message.split())
        self.exit(2, f"{self.prog}: error: {line} (--help for usage)\n")


def _number(text: str) -> float:
    try:
        x = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not math.isfinite(x):
        raise argparse.ArgumentTypeError(f"{text!r}: expected a finite number")
    return x


def _outside(text: str, lo: float | None, hi: float | None, lo_open: bool = False) -> str:
    """The message of a value `text` outside [lo, hi] (lo excluded with `lo_open`)."""
    if lo is not None and hi is not None:
        return f"{text} is outside {'(' if lo_open else '['}{lo:g}, {hi:g}]"
    if lo is not None:
        return f"{text}: expected a value {'>' if lo_open else '≥'} {lo:g}"
    return f"{text}: expected a value ≤ {hi:g}"


def number(lo: float | None = None, hi: float | None = None, *, lo_open: bool = False) -> Callable[[str], float]:
    """An argparse `type`: a finite float in [lo, hi] (lo excluded with `lo_open`)."""

    def parse(text: str) -> float:
        x = _number(text)
        below = lo is not None and (x <= lo if lo_open else x < lo)
        if below or (hi is not None and x > hi):
            raise argparse.ArgumentTypeError(_outside(text, lo, hi, lo_open))
        return x

    parse.__name__ = "number"
    return parse


def integer(lo: int | None = None, hi: int | None = None) -> Callable[[str], int]:
    """An argparse `type`: a whole number in [lo, hi]."""

    def parse(text: str) -> int:
        try:
            n = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
        if (lo is not None and n < lo) or (hi is not None and n > hi):
            raise argparse.ArgumentTypeError(_outside(text, lo, hi))
        return n

    parse.__name__ = "integer"
    return parse


def declared(model: str, name: str) -> Callable[[str], float]:
    """An argparse `type`: a finite float within the declared range of `model`'s variable `name`."""
    v = declarations.VARIABLES[model][name]
    return number(v.min, v.max)


def declared_mission(name: str) -> Callable[[str], float]:
    """An argparse `type`: a finite float within the declared range of the mission parameter `name`."""
    lo, hi = declarations.MISSION_RANGES[name]
    return number(lo, hi)


def declared_magnitude(model: str, name: str) -> Callable[[str], float]:
    """An argparse `type`: a magnitude (≥ 0) of a signed declared variable, at most its largest |value|."""
    v = declarations.VARIABLES[model][name]
    bounds = [abs(b) for b in (v.min, v.max) if b is not None]
    return number(0.0, max(bounds) if bounds else None)


def choices_list(allowed: Sequence[str]) -> Callable[[str], tuple[str, ...]]:
    """An argparse `type`: a comma-separated list of distinct names out of `allowed`, at least one."""

    def parse(text: str) -> tuple[str, ...]:
        items = tuple(s.strip() for s in text.split(","))
        bad = [s for s in items if s not in allowed]
        if bad or not items:
            unknown = ", ".join(map(repr, bad))
            raise argparse.ArgumentTypeError(f"{text!r}: unknown {unknown} (choose from {', '.join(allowed)})")
        if len(set(items)) != len(items):
            raise argparse.ArgumentTypeError(f"{text!r}: a name is repeated")
        return items

    parse.__name__ = "list"
    return parse


def fmu_problem(path: pathlib.Path) -> str | None:
    """Why `path` is not a usable .fmu (missing, not a zip archive, no modelDescription.xml), or None."""
    if not path.is_file():
        return f"{path} is missing"
    if not zipfile.is_zipfile(path):
        return f"{path} is not a readable FMU (not a zip archive)"
    try:
        with zipfile.ZipFile(path) as z:
            if "modelDescription.xml" not in z.namelist():
                return f"{path} is not an FMU (no modelDescription.xml inside)"
    except (OSError, zipfile.BadZipFile) as e:
        return f"{path} is not a readable FMU ({e})"
    return None


#: The source checkout the package runs from (None when installed elsewhere).
SOURCE_ROOT = pathlib.Path(__file__).resolve().parents[2]

#: The files an FMU is built from: their newest change must not postdate the FMU.
SOURCE_GLOBS = (
    "crates/*/src/**/*.rs",
    "fmu-*/src/**/*.rs",
    "modelDescription/*.json",
    "modelDescription/fragments/*.json",
)


def newest_source(root: pathlib.Path | None = None) -> pathlib.Path | None:
    """The most recently modified FMU source file of a source checkout at `root` (default
    [`SOURCE_ROOT`]; None outside a checkout)."""
    root = SOURCE_ROOT if root is None else root
    if not (root / "Cargo.toml").is_file() or not (root / "modelDescription").is_dir():
        return None
    files = (f for g in SOURCE_GLOBS for f in root.glob(g) if f.is_file())
    return max(files, key=lambda f: f.stat().st_mtime, default=None)


def stale_fmus(dist: str | pathlib.Path, models: Iterable[str], root: pathlib.Path | None = None) -> list[str]:
    """One line per `<model>.fmu` in `dist` older than the newest FMU source of the checkout
    at `root` (default [`SOURCE_ROOT`]; built before a change: its results would be the old
    code's)."""
    root = SOURCE_ROOT if root is None else root
    src = newest_source(root)
    if src is None:
        return []
    t = src.stat().st_mtime
    out = []
    for m in models:
        f = pathlib.Path(dist) / f"{m}.fmu"
        if f.is_file() and f.stat().st_mtime < t:
            out.append(f"{f} is older than {src.relative_to(root)}: its results are the previous build's; {BUILD_HINT}")
    return out


def check_fmus(
    parser: argparse.ArgumentParser,
    option: str,
    dist: str | pathlib.Path,
    models: Iterable[str],
    root: pathlib.Path | None = None,
) -> None:
    """`parser.error` unless folder `dist` holds a readable `<model>.fmu` of every model; a
    warning on stderr for each FMU older than the checkout's sources (`stale_fmus`)."""
    dist = pathlib.Path(dist)
    if not dist.is_dir():
        parser.error(f"argument {option}: {str(dist)!r} is not a folder of FMUs; {BUILD_HINT}")
    models = list(models)
    for m in models:
        problem = fmu_problem(dist / f"{m}.fmu")
        if problem:
            parser.error(f"argument {option}: {problem}; {BUILD_HINT}")
    for line in stale_fmus(dist, models, root):
        print(f"{parser.prog}: warning: {line}", file=sys.stderr)


def check_out(parser: argparse.ArgumentParser, option: str, out: str | pathlib.Path) -> None:
    """`parser.error` if the output folder `out` exists as something other than a folder."""
    p = pathlib.Path(out)
    if p.exists() and not p.is_dir():
        parser.error(f"argument {option}: {str(p)!r} exists and is not a folder")


def guard(prog: str, debug: bool, body: Callable[[], int | None]) -> int:
    """Run `body`; an unexpected error becomes one line on stderr and exit code 1
    (re-raised with `debug`, for its traceback)."""
    try:
        return body() or 0
    except KeyboardInterrupt:
        print(f"{prog}: interrupted", file=sys.stderr)
        return 130
    except Exception as e:
        if debug:
            raise
        text = " ".join(str(e).split()) or "(no message)"
        print(f"{prog}: error: {type(e).__name__}: {text} (--debug for the traceback)", file=sys.stderr)
        return 1
