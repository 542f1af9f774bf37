"""Catalogs of motors, gearboxes and drives (:func:`load_catalog`, :class:`Catalog`).

A catalog is a folder holding ``motors.csv`` and ``gearboxes.csv`` (and, for the drive checks,
``drives.csv``), or single CSV files, one part per row, SI units (speeds in rad/s, inertias in
kg m², temperatures in °C, lives in hours). Every column is declared once, here, with its unit,
whether it is required, its bounds and its meaning: :data:`MOTOR_COLUMNS`,
:data:`GEARBOX_COLUMNS`, :data:`DRIVE_COLUMNS` (docs/api.md's tables are generated from them by
:func:`column_table`).

Reading rules (every row is checked before anything is returned):

- A file is read as the URDF loader reads its own: a regular file (never a FIFO, a directory or a
  device such as ``/dev/zero``) of at most :data:`MAX_CATALOG_BYTES` bytes (64 MiB), UTF-8 text
  (a UTF-8 byte-order mark is skipped; CRLF, LF and CR line ends are all accepted).
- The first non-blank row is the header; blank rows (also rows of empty cells, as spreadsheets
  export them) are skipped. Cells are stripped of surrounding blanks. Every row has as many
  cells as the header.
- A numeric cell is a decimal number (``12``, ``-0.5``, ``1.2e-4``); ``nan``, ``inf`` and a
  number that overflows (``1e400``) are refused. A blank cell of an optional column is NaN (or
  the column's default: ``life_exponent`` 3); of a required column, an error. A value outside
  the column's bounds is an error. Columns given together (the two-node thermal model's four,
  the gear life's rated speed and life, the bearing rating's load and pitch diameter) are
  checked as a group, and a bearing allowable or rating needs ``bearing_offset``. Ordered
  columns (continuous ≤ peak torque and current, rated ≤ repeated peak ≤ momentary peak torque,
  bus voltage ≤ maximum bus voltage) are checked on every row.
- Columns not declared here are kept as they are: as floats when every cell is a number or
  blank (blank: NaN), else as text. One that looks like a misspelt declared column
  (``max_winding_temp``) gives a UserWarning naming the column it resembles.
- Part names are unique per kind, across all the paths merged.

Every error is an :class:`armdyn.ModelError` naming the file, the line (1-based, as an editor
counts it), and the column; a missing or unreadable path is the ``OSError`` that names it.

DataFrames are checked by the same rules (:class:`Catalog` / :meth:`Catalog.from_frames`; a bad
value is named by table, row and part). :func:`synthetic_catalog` makes large catalogs of
made-up parts for benchmarks.
"""

from __future__ import annotations

import csv
import io
import math
import os
import re
from collections.abc import Mapping
from dataclasses import dataclass, field, make_dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from armdyn import _checks, _core

if TYPE_CHECKING:
    pass

#: the largest catalog file read [bytes] (the URDF loader's bound, 64 MiB)
MAX_CATALOG_BYTES = _core.URDF_MAX_BYTES
#: the folder of the example catalog shipped with armdyn (motors.csv, gearboxes.csv, drives.csv)
EXAMPLE_CATALOG = Path(__file__).resolve().parent / "example_catalog"
#: the part kinds, and the file name of each in a catalog folder
KINDS = ("motors", "gearboxes", "drives")
FILE_NAMES = {kind: f"{kind}.csv" for kind in KINDS}
_ONE = {"motors": "motor", "gearboxes": "gearbox", "drives": "drive"}


@dataclass(frozen=True)
class Column:
    """One catalog column.

    Attributes:
        name: the CSV header name (and the DataFrame column, the dataclass field).
        unit: its unit ("" for text, "1" for a pure number).
        required: a missing column, or a blank cell in it, is an error.
        doc: what it is.
        lo, hi: bounds (None: unbounded); ``lo_open``: the value must be > lo (else >= lo).
        default: an optional column's value when blank or absent (None: NaN).
        text: a text column (name, source).
    """

    name: str
    unit: str
    required: bool
    doc: str
    lo: float | None = 0.0
    lo_open: bool = True
    hi: float | None = None
    default: float | None = None
    text: bool = False

    @property
    def allowed(self) -> str:
        """The bounds in words ("> 0", "in (0, 1]", "any finite number")."""
        if self.text:
            return "text"
        if self.lo is not None and self.hi is not None:
            return f"in {'(' if self.lo_open else '['}{self.lo:g}, {self.hi:g}]"
        if self.lo is not None:
            return f"{'>' if self.lo_open else '>='} {self.lo:g}"
        if self.hi is not None:
            return f"<= {self.hi:g}"
        return "any finite number"

    def out_of_bounds(self, x: np.ndarray) -> np.ndarray:
        """Where the (non-NaN) values ``x`` break the bounds."""
        bad = np.zeros(x.shape, dtype=bool)
        with np.errstate(invalid="ignore"):
            if self.lo is not None:
                bad |= (x <= self.lo) if self.lo_open else (x < self.lo)
            if self.hi is not None:
                bad |= x > self.hi
        return bad & ~np.isnan(x)


def _name(doc: str) -> Column:
    return Column("name", "", True, doc, text=True)


_SOURCE = Column(
    "source",
    "",
    False,
    'where the values come from: "illustrative", or the public datasheet they are taken from',
    text=True,
)
_COST = Column(
    "cost", "any", False, "price (any currency, the same in one catalog)", lo=0.0, lo_open=False
)

MOTOR_COLUMNS: tuple[Column, ...] = (
    _name("the motor's part name (unique among the motors)"),
    Column("torque_constant", "N m/A", True, "torque per ampere, k_t"),
    Column("resistance", "ohm", True, "terminal resistance at the resistance temperature"),
    Column("rotor_inertia", "kg m^2", True, "the rotor's moment of inertia (motor side)"),
    Column("mass", "kg", True, "the motor's mass (carried by the arm)"),
    Column("continuous_torque", "N m", True, "continuous (rated) torque"),
    Column("peak_torque", "N m", True, "peak torque (at least the continuous torque)"),
    Column("no_load_speed", "rad/s", False, "no-load speed at the rated voltage"),
    Column("max_speed", "rad/s", False, "maximum (mechanical or rated) speed"),
    Column("voltage", "V", False, "rated supply voltage of the speed-torque envelope"),
    Column(
        "thermal_resistance_winding",
        "K/W",
        False,
        "two-node thermal model: winding to housing (the four two-node columns go together)",
    ),
    Column("thermal_resistance_housing", "K/W", False, "two-node model: housing to ambient"),
    Column("thermal_time_constant_winding", "s", False, "two-node model: the winding's"),
    Column("thermal_time_constant_housing", "s", False, "two-node model: the housing's"),
    Column("max_winding_temperature", "degC", False, "the winding's largest allowed temperature"),
    Column("thermal_resistance", "K/W", False, "one-node model: winding to ambient"),
    Column("thermal_time_constant", "s", False, "one-node model: the winding's"),
    Column("brake_torque", "N m", False, "holding brake torque (motor side); blank: no brake"),
    _COST,
    _SOURCE,
)

GEARBOX_COLUMNS: tuple[Column, ...] = (
    _name("the gearbox's part name (unique; a series in several ratios is several rows)"),
    Column("ratio", "1", True, "reduction ratio N (input speed / output speed)"),
    Column("efficiency", "1", True, "efficiency, constant per row", hi=1.0),
    Column("input_inertia", "kg m^2", True, "moment of inertia at the input", lo_open=False),
    Column("mass", "kg", True, "the gearbox's mass (carried by the arm)"),
    Column("rated_torque", "N m", True, "rated output torque T_N (at the rated input speed)"),
    Column("rated_input_speed", "rad/s", False, "input speed n_N of the rated life"),
    Column("rated_life", "h", False, "rated life L_N at T_N and n_N (L10 or L50, as given)"),
    Column(
        "life_exponent",
        "1",
        False,
        "exponent p of L = L_N (T_N/T_av)^p (n_N/n_av): 3 (strain wave), 10/3 (RV)",
        hi=20.0,
        default=3.0,
    ),
    Column(
        "average_torque_limit",
        "N m",
        False,
        "limit for the mean output torque (exponent life_exponent)",
    ),
    Column("average_input_speed_limit", "rad/s", False, "limit for the average input speed"),
    Column("repeated_peak_torque", "N m", True, "limit for repeated peak (start/stop) torque"),
    Column("momentary_peak_torque", "N m", False, "limit for momentary (emergency stop) torque"),
    Column("momentary_peak_count", "1", False, "allowed number of momentary peaks over the life"),
    Column("max_input_speed", "rad/s", False, "maximum input speed"),
    Column("bearing_moment_allowable", "N m", False, "output bearing: allowable tilting moment"),
    Column("bearing_axial_allowable", "N", False, "output bearing: allowable axial force"),
    Column("bearing_radial_allowable", "N", False, "output bearing: allowable radial force"),
    Column(
        "bearing_offset",
        "m",
        False,
        "output bearing: the signed distance of its reference point from the joint point "
        "along the joint axis (the bearing checks document the sign)",
        lo=None,
    ),
    Column("bearing_dynamic_load_rating", "N", False, "output bearing: dynamic load rating C"),
    Column("bearing_pitch_diameter", "m", False, "output bearing: roller pitch diameter d_p"),
    _COST,
    _SOURCE,
)

DRIVE_COLUMNS: tuple[Column, ...] = (
    _name("the drive's part name (unique among the drives)"),
    Column("continuous_current", "A", True, "continuous output current (RMS over the cycle)"),
    Column("peak_current", "A", True, "peak output current"),
    Column("bus_voltage", "V", True, "nominal DC bus voltage"),
    Column(
        "max_bus_voltage",
        "V",
        False,
        "bus voltage at which the braking resistor switches in (the capacitance absorbs "
        "regenerated energy up to it)",
    ),
    Column("bus_capacitance", "F", False, "DC bus capacitance"),
    Column("braking_resistor_power", "W", False, "braking resistor: continuous power"),
    Column("braking_resistor_peak_power", "W", False, "braking resistor: peak power"),
    Column("mass", "kg", False, "the drive's mass (not carried by the arm)"),
    _COST,
    _SOURCE,
)

#: the columns of each kind
COLUMNS: dict[str, tuple[Column, ...]] = {
    "motors": MOTOR_COLUMNS,
    "gearboxes": GEARBOX_COLUMNS,
    "drives": DRIVE_COLUMNS,
}
_BY_NAME = {kind: {c.name: c for c in cols} for kind, cols in COLUMNS.items()}

#: columns given together or not at all
_GROUPS = {
    "motors": (
        (
            "thermal_resistance_winding",
            "thermal_resistance_housing",
            "thermal_time_constant_winding",
            "thermal_time_constant_housing",
        ),
    ),
    "gearboxes": (
        ("rated_input_speed", "rated_life"),
        ("bearing_dynamic_load_rating", "bearing_pitch_diameter"),
    ),
    "drives": (),
}
#: (column, the column it needs): a bearing allowable or rating needs the bearing's offset
_NEEDS = {
    "motors": (),
    "gearboxes": tuple(
        (c, "bearing_offset")
        for c in (
            "bearing_moment_allowable",
            "bearing_axial_allowable",
            "bearing_radial_allowable",
            "bearing_dynamic_load_rating",
        )
    ),
    "drives": (),
}
#: (smaller, larger) pairs checked on every row where both are given
_ORDERED = {
    "motors": (("continuous_torque", "peak_torque"),),
    "gearboxes": (
        ("rated_torque", "repeated_peak_torque"),
        ("repeated_peak_torque", "momentary_peak_torque"),
    ),
    "drives": (("continuous_current", "peak_current"), ("bus_voltage", "max_bus_voltage")),
}

_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")


def _dataclass(cls_name: str, kind: str, what: str):
    cols = COLUMNS[kind]
    fields_ = [(c.name, str if c.text else float) for c in cols]
    # the other columns, left out of the hash (a dict is not hashable)
    fields_.append(("extra", Mapping[str, Any], field(default_factory=dict, hash=False)))
    cls = make_dataclass(cls_name, fields_, frozen=True)
    cls.__module__ = __name__  # (make_dataclass takes module= from Python 3.12)
    lines = [
        f"One {what} of a :class:`Catalog` (frozen; fields in SI units, NaN when not given).",
        "",
    ]
    lines.append("Attributes:")
    for c in cols:
        unit = f" [{c.unit}]" if c.unit not in ("", "1") else ""
        lines.append(f"    {c.name}: {c.doc}{unit}.")
    lines.append("    extra: the row's other (undeclared) columns, by name (a dict).")
    cls.__doc__ = "\n".join(lines)
    return cls


Gearbox = _dataclass("Gearbox", "gearboxes", "gearbox")
Drive = _dataclass("Drive", "drives", "drive")


class Catalog:
    """Motors, gearboxes and drives (from :func:`load_catalog` or :meth:`from_frames`).

    Attributes:
        motors, gearboxes, drives: pandas DataFrames indexed by part name (``name``): the
            declared columns (:data:`MOTOR_COLUMNS`, ...) in their declared order as floats in
            SI units (text for ``source``), NaN where an optional value is not given, then any
            undeclared columns. A kind the catalog has no file for has no rows.
        paths: the files read, in order.
    """

    def __init__(self, motors=None, gearboxes=None, drives=None) -> None:
        """A catalog from DataFrames (or mappings of columns, or None for no parts), each
        indexed by part name or with a ``name`` column, checked by the rules of the CSV files
        (a bad value is a ModelError naming the table, the part and the column); the same as
        :meth:`from_frames`. :func:`load_catalog` reads files."""
        tables, origins = {}, {}
        for kind, frame in zip(KINDS, (motors, gearboxes, drives), strict=True):
            tables[kind], where = _frame_table(kind, frame)
            origins.update({(kind, n): w for n, w in zip(tables[kind].index, where, strict=True)})
        self._set(tables, (), origins)

    def _set(self, tables: dict, paths, origins: dict) -> None:
        self.motors = tables["motors"]
        self.gearboxes = tables["gearboxes"]
        self.drives = tables["drives"]
        self.paths = tuple(paths)
        self._origins = dict(origins)

    @classmethod
    def _checked(cls, tables: dict, paths, origins: dict) -> Catalog:
        """A catalog of tables already checked (load_catalog's)."""
        self = cls.__new__(cls)
        self._set(tables, paths, origins)
        return self

    def __repr__(self) -> str:
        return (
            f"Catalog({len(self.motors)} motors, {len(self.gearboxes)} gearboxes, "
            f"{len(self.drives)} drives)"
        )

    @classmethod
    def from_frames(cls, motors=None, gearboxes=None, drives=None) -> Catalog:
        """A catalog from DataFrames (or mappings of columns, or None), checked by the rules of
        the CSV files: each indexed by part name, or with a ``name`` column. A bad value is a
        ModelError naming the table, the part and the column."""
        return cls(motors, gearboxes, drives)

    def _row(self, kind: str, name: str):
        table = getattr(self, kind)
        if not isinstance(name, str) or name not in table.index:
            shown = list(table.index[:10]) + (["..."] if len(table) > 10 else [])
            raise _core.ModelError(f"catalog: no {_ONE[kind]} named {name!r} (the {kind}: {shown})")
        return table.loc[name]

    def motor(self, name: str):
        """The motor ``name`` as an :class:`armdyn.Motor` (its MOTOR_FIELDS from the row)."""
        return _motor_from_row(self._row("motors", name), name)

    def gearbox(self, name: str) -> Any:
        """The gearbox ``name`` as a frozen :class:`Gearbox`."""
        return _part(Gearbox, "gearboxes", self._row("gearboxes", name), name)

    def drive(self, name: str) -> Any:
        """The drive ``name`` as a frozen :class:`Drive`."""
        return _part(Drive, "drives", self._row("drives", name), name)

    def origin(self, kind: str, name: str) -> str:
        """Where the part was read (``file:line``, or the table and part for a DataFrame)."""
        self._row(kind, name)
        return self._origins[(kind, name)]


def _motor_from_row(row, name: str):
    from_row = getattr(_core.Motor, "from_row", None)
    if from_row is not None:
        row = row.copy()
        row.name = name
        return from_row(row)
    from armdyn.sizing import what_if

    kw = {}
    for key in what_if.MOTOR_FIELDS:
        if key == "name" or key not in row.index:
            continue
        value = row[key]
        if isinstance(value, float) and math.isnan(value):
            continue
        kw[key] = float(value)
    return _core.Motor(name=name, **kw)


def _part(cls, kind: str, row, name: str):
    declared = _BY_NAME[kind]
    values = {"name": name}
    for c in COLUMNS[kind][1:]:
        value = row[c.name]
        values[c.name] = str(value) if c.text else float(value)
    extra = {k: row[k] for k in row.index if k not in declared}
    return cls(**values, extra=extra)


# --- reading -----------------------------------------------------------------------------------


def load_catalog(path, *more) -> Catalog:
    """The catalog at ``path`` (and ``more`` paths, merged): each a folder holding
    ``motors.csv`` and ``gearboxes.csv`` (and optionally ``drives.csv``), or a single CSV file
    whose kind is told by its name (``motors.csv``, ``my_motors.csv``, ``gearboxes.csv``,
    ``drives.csv``...) or else by its header (the kind whose required columns it has). Every
    row is checked (the module notes give the rules); a part name met twice (in one file or
    across the paths) is a ModelError naming both places. ``armdyn.sizing.EXAMPLE_CATALOG`` is
    the example shipped with armdyn."""
    files: list[tuple[str | None, Path]] = []
    for k, p in enumerate((path, *more)):
        if not isinstance(p, (str, os.PathLike)):
            raise _core.ModelError(
                f"load_catalog: path {k + 1} must be a str or a path, got {type(p).__name__}"
            )
        text = os.fspath(p)
        if not isinstance(text, str) or "\x00" in text:
            raise _core.ModelError(
                f"load_catalog: path {k + 1} must be a str path without NUL characters, got "
                f"{text!r:.60}"
            )
        files.extend(_files_of(Path(text)))
    parsed: dict[str, list] = {kind: [] for kind in KINDS}
    for kind, file in files:
        header, rows, lines = _read_csv(file)
        kind = kind or _kind_of(file, header)
        parsed[kind].append(_csv_table(kind, file, header, rows, lines))
    tables, origins = {}, {}
    for kind in KINDS:
        tables[kind], where = _merge(kind, parsed[kind])
        origins.update({(kind, n): w for n, w in zip(tables[kind].index, where, strict=True)})
    return Catalog._checked(tables, [f for _, f in files], origins)


def _files_of(path: Path) -> list[tuple[str | None, Path]]:
    """The CSV files of a catalog path (kind None: told by the file later)."""
    if not path.exists():
        raise FileNotFoundError(2, "catalog path not found", str(path))
    if not path.is_dir():
        return [(None, path)]
    out = [(kind, path / FILE_NAMES[kind]) for kind in KINDS if (path / FILE_NAMES[kind]).exists()]
    missing = [
        FILE_NAMES[k] for k in ("motors", "gearboxes") if not (path / FILE_NAMES[k]).exists()
    ]
    if missing:
        raise _core.ModelError(
            f"catalog folder {str(path)!r} has no {' and no '.join(missing)} (a catalog folder "
            "holds motors.csv, gearboxes.csv and optionally drives.csv)"
        )
    others = sorted(
        p.name
        for p in path.iterdir()
        if p.suffix.lower() == ".csv" and p.name not in FILE_NAMES.values()
    )
    if others:
        raise _core.ModelError(
            f"catalog folder {str(path)!r}: unrecognised CSV file(s) {others} (a catalog folder "
            "holds motors.csv, gearboxes.csv and drives.csv; pass other files as paths of "
            "their own)"
        )
    return out


def _text_of(path: Path) -> str:
    data = _checks.regular_file(path, "catalog file", MAX_CATALOG_BYTES)
    if data.startswith(b"\xef\xbb\xbf"):
        data = data[3:]
    nul = data.find(b"\x00")
    if nul >= 0:
        line = _line_of(data, nul)
        raise _core.ModelError(
            f"{path}:{line}: a NUL byte (offset {nul}): not UTF-8 text (a binary or UTF-16 file?)"
        )
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as err:
        line = _line_of(data, err.start)
        raise _core.ModelError(
            f"{path}:{line}: not UTF-8 text (byte {data[err.start : err.start + 1]!r} at offset "
            f"{err.start}); save the catalog as UTF-8"
        ) from None


def _line_of(data: bytes, offset: int) -> int:
    """The 1-based line of a byte offset (CRLF, LF and CR line ends, as the CSV reader)."""
    return len(re.split(rb"\r\n|\r|\n", data[:offset]))


def _read_csv(path: Path) -> tuple[list[str], list[list[str]], list[int]]:
    """(header, data rows, each data row's first line): blank rows skipped, cells stripped."""
    text = _text_of(path)
    reader = csv.reader(io.StringIO(text, newline=""), strict=True)
    header, rows, lines = None, [], []
    while True:
        line = reader.line_num + 1
        try:
            row = next(reader)
        except StopIteration:
            break
        except csv.Error as err:
            raise _core.ModelError(f"{path}:{line}: malformed CSV ({err})") from None
        cells = [c.strip() for c in row]
        if not any(cells):
            continue
        if header is None:
            header = _header(path, line, cells)
            continue
        if len(cells) != len(header):
            raise _core.ModelError(
                f"{path}:{line}: the row has {len(cells)} cells, the header {len(header)}"
            )
        rows.append(cells)
        lines.append(line)
    if header is None:
        raise _core.ModelError(f"{path}: empty catalog file (no header row)")
    if not rows:
        raise _core.ModelError(f"{path}: no parts (a header row and no data rows)")
    return header, rows, lines


def _header(path: Path, line: int, cells: list[str]) -> list[str]:
    for k, name in enumerate(cells):
        if not name:
            raise _core.ModelError(f"{path}:{line}: header cell {k + 1} is empty")
    seen = set()
    for name in cells:
        if name in seen:
            raise _core.ModelError(f"{path}:{line}: column {name!r} appears twice in the header")
        seen.add(name)
    return cells


def _kind_of(path: Path, header: list[str]) -> str:
    stem = path.stem.lower()
    for kind in KINDS:
        if stem == kind or re.search(rf"[_\-. ]{kind}$", stem):
            return kind
    fits = [k for k in KINDS if {c.name for c in COLUMNS[k] if c.required} <= set(header)]
    if len(fits) == 1:
        return fits[0]
    names = ", ".join(FILE_NAMES.values())
    if not fits:
        raise _core.ModelError(
            f"{path}: which kind of part? The file name is none of {names} and its header has "
            "the required columns of no kind ("
            + "; ".join(f"{k}: missing {_missing(k, header)}" for k in KINDS)
            + ")"
        )
    raise _core.ModelError(f"{path}: which kind of part? Its header fits {fits}: name it {names}")


def _missing(kind: str, header) -> list[str]:
    return [c.name for c in COLUMNS[kind] if c.required and c.name not in header]


@dataclass
class _Table:
    """One file's (or frame's) parts before merging: the columns as arrays, and where each row
    came from (for messages)."""

    kind: str
    names: list[str]
    values: dict[str, Any]  # column -> float array, or list of str (text columns)
    where: list[str]  # "file:line" per row
    extras: list[str]


def _csv_table(kind: str, path: Path, header, rows, lines) -> _Table:
    missing = _missing(kind, header)
    if missing:
        raise _core.ModelError(f"{path}: missing required column(s) {missing} of {kind}")
    where = [f"{path}:{line}" for line in lines]
    by_name = _BY_NAME[kind]
    values: dict[str, Any] = {}
    for k, col in enumerate(header):
        cells = [r[k] for r in rows]
        c = by_name.get(col)
        if c is None:
            values[col] = _extra_values(cells)
        elif c.text:
            values[col] = cells
        else:
            values[col] = _numbers(cells, col, where)
    extras = [h for h in header if h not in by_name]
    _near_misses(kind, str(path), extras)
    return _check_table(_Table(kind, values["name"], values, where, extras))


def _near_misses(kind: str, where: str, extras: list[str]) -> None:
    """A UserWarning for each undeclared column that looks like a misspelt declared one (kept,
    but its check would go unchecked)."""
    import difflib
    import warnings

    for e in extras:
        close = difflib.get_close_matches(e, list(_BY_NAME[kind]), n=1, cutoff=0.8)
        if close:
            warnings.warn(
                f"{where}: column {e!r} is not a {_ONE[kind]} column (kept as an extra); "
                f"did you mean {close[0]!r}?",
                UserWarning,
                stacklevel=4,
            )


def _numbers(cells: list[str], col: str, where: list[str]) -> np.ndarray:
    out = np.empty(len(cells))
    for i, text in enumerate(cells):
        if not text:
            out[i] = np.nan
            continue
        x = float(text) if _NUMBER.fullmatch(text) else math.nan
        if not math.isfinite(x):
            why = "overflows a float" if _NUMBER.fullmatch(text) else "is not a finite number"
            raise _core.ModelError(f"{where[i]}: column {col!r}: {text[:40]!r} {why}")
        out[i] = x
    return out


def _extra_values(cells: list[str]):
    """An undeclared column: floats when every non-blank cell is a finite number, else text."""
    if all(not t or _NUMBER.fullmatch(t) for t in cells):
        x = np.array([float(t) if t else np.nan for t in cells])
        if np.all(np.isfinite(x) | np.array([not t for t in cells])):
            return x
    return list(cells)


def _check_table(t: _Table) -> _Table:
    """Every rule of the module notes on one table (names, required, bounds, groups, order);
    the first offence is a ModelError naming the row's place and the column."""
    names = [str(n) for n in t.names]
    for i, n in enumerate(names):
        if not n:
            raise _core.ModelError(f"{t.where[i]}: column 'name': empty part name")
        if any(ord(ch) < 32 for ch in n):
            raise _core.ModelError(f"{t.where[i]}: column 'name': {n!r} has control characters")
    t.names = names
    _duplicates(t.kind, names, t.where)
    for c in COLUMNS[t.kind][1:]:
        if c.text:
            t.values[c.name] = [str(v) for v in t.values.get(c.name, [""] * len(names))]
            continue
        x = t.values.get(c.name)
        x = np.full(len(names), np.nan) if x is None else np.asarray(x, dtype=float)
        bad = np.flatnonzero(np.isnan(x)) if c.required else []
        if len(bad):
            raise _core.ModelError(
                f"{t.where[bad[0]]}: column {c.name!r}: a value is required ({c.unit}, {c.allowed})"
            )
        bad = np.flatnonzero(c.out_of_bounds(x) | np.isinf(x))
        if len(bad):
            i = bad[0]
            raise _core.ModelError(
                f"{t.where[i]}: column {c.name!r}: {float(x[i])!r} must be {c.allowed} [{c.unit}]"
            )
        if c.default is not None:
            x = np.where(np.isnan(x), c.default, x)
        t.values[c.name] = x
    _relations(t)
    return t


def _relations(t: _Table) -> None:
    v = t.values
    for group in _GROUPS[t.kind]:
        given = np.stack([~np.isnan(v[c]) for c in group])
        partial = np.flatnonzero(given.any(axis=0) & ~given.all(axis=0))
        if len(partial):
            i = partial[0]
            lacking = [c for k, c in enumerate(group) if not given[k, i]]
            raise _core.ModelError(
                f"{t.where[i]}: column(s) {lacking}: {list(group)} are given together or not at all"
            )
    for col, needed in _NEEDS[t.kind]:
        bad = np.flatnonzero(~np.isnan(v[col]) & np.isnan(v[needed]))
        if len(bad):
            raise _core.ModelError(f"{t.where[bad[0]]}: column {needed!r}: {col} needs it")
    for small, large in _ORDERED[t.kind]:
        with np.errstate(invalid="ignore"):
            bad = np.flatnonzero(v[small] > v[large])
        if len(bad):
            i = bad[0]
            raise _core.ModelError(
                f"{t.where[i]}: column {large!r}: {float(v[large][i])!r} is less than {small} "
                f"{float(v[small][i])!r}"
            )


def _duplicates(kind: str, names: list[str], where: list[str]) -> None:
    first: dict[str, int] = {}
    for i, n in enumerate(names):
        if n in first:
            raise _core.ModelError(
                f"{where[i]}: column 'name': {_ONE[kind]} {n!r} is already at {where[first[n]]}"
            )
        first[n] = i


def _merge(kind: str, tables: list[_Table]):
    """One DataFrame per kind (declared columns, then the extras in order of appearance)."""
    import pandas as pd

    names = [n for t in tables for n in t.names]
    where = [w for t in tables for w in t.where]
    _duplicates(kind, names, where)
    data: dict[str, Any] = {}
    for c in COLUMNS[kind][1:]:
        if c.text:
            data[c.name] = [s for t in tables for s in t.values[c.name]]
        else:
            data[c.name] = np.concatenate([t.values[c.name] for t in tables] or [np.empty(0)])
    extras = list(dict.fromkeys(e for t in tables for e in t.extras))
    for e in extras:
        parts = [_extra_or_blank(t, e) for t in tables]
        if all(isinstance(p, np.ndarray) for p in parts):
            data[e] = np.concatenate(parts)
        else:
            data[e] = [
                str(x) if not (isinstance(x, float) and np.isnan(x)) else ""
                for p in parts
                for x in p
            ]
    frame = pd.DataFrame(data, index=pd.Index(names, name="name", dtype=object))
    return frame, where


def _extra_or_blank(t: _Table, col: str):
    if col in t.values:
        return t.values[col]
    return np.full(len(t.names), np.nan)


def _frame_table(kind: str, frame):
    """A DataFrame (or mapping of columns, or None) checked as a table of ``kind``."""
    import pandas as pd

    if frame is None:
        frame = pd.DataFrame({c.name: [] for c in COLUMNS[kind]})
    if isinstance(frame, Mapping):
        try:
            frame = pd.DataFrame(dict(frame))
        except (ValueError, TypeError) as err:
            raise _core.ModelError(
                f"Catalog.from_frames: {kind} is not a table of columns ({err})"
            ) from None
    if not isinstance(frame, pd.DataFrame):
        raise _core.ModelError(
            f"Catalog.from_frames: {kind} must be a DataFrame, a mapping of columns or None, "
            f"got {type(frame).__name__}"
        )
    if "name" not in frame.columns:
        if isinstance(frame.index, pd.RangeIndex) and len(frame):
            raise _core.ModelError(
                f"Catalog.from_frames: {kind} needs a 'name' column or an index of part names"
            )
        frame = frame.rename_axis("name").reset_index()
    header = [str(c) for c in frame.columns]
    if len(set(header)) != len(header):
        twice = sorted({h for h in header if header.count(h) > 1})
        raise _core.ModelError(f"Catalog.from_frames: {kind} has column(s) {twice} twice")
    missing = _missing(kind, header)
    if missing:
        raise _core.ModelError(f"Catalog.from_frames: {kind} lacks required column(s) {missing}")
    names = ["" if _blank(n) else str(n) for n in frame["name"]]
    where = [f"{kind} table, row {i + 1}, part {n!r}" for i, n in enumerate(names)]
    by_name = _BY_NAME[kind]
    values: dict[str, Any] = {}
    for col in header:
        c = by_name.get(col)
        series = frame[col]
        if c is not None and not c.text:
            values[col] = _frame_numbers(series, col, where)
        elif c is not None:
            values[col] = ["" if _blank(v) else str(v) for v in series]
        else:
            values[col] = series.to_numpy()
    extras = [h for h in header if h not in by_name]
    _near_misses(kind, f"{kind} table", extras)
    t = _check_table(_Table(kind, names, values, where, extras))
    return _merge(kind, [t])


def _blank(v) -> bool:
    """None, a NaN (Python's or numpy's) or pandas' NA: a cell not given."""
    if v is None or type(v).__name__ == "NAType":
        return True
    return isinstance(v, (float, np.floating)) and math.isnan(v)


def _frame_numbers(series, col: str, where: list[str]) -> np.ndarray:
    out = np.empty(len(series))
    for i, v in enumerate(series.tolist()):
        if _blank(v):
            out[i] = np.nan
            continue
        if isinstance(v, (bool, np.bool_, complex, np.complexfloating)) or not isinstance(
            v, (int, float, np.number)
        ):
            raise _core.ModelError(f"{where[i]}: column {col!r}: {v!r} is not a number")
        out[i] = float(v)
        if not math.isfinite(out[i]):
            raise _core.ModelError(f"{where[i]}: column {col!r}: {v!r} is not a finite number")
    return out


# --- a synthetic catalog (benchmarks, tests) ----------------------------------------------------

_RATIOS = (50.0, 80.0, 100.0, 120.0, 160.0)
#: strain-wave rated torque per ratio, relative to ratio 100 (the example catalog's pattern)
_RATIO_TORQUE = {50.0: 0.6, 80.0: 0.94, 100.0: 1.0, 120.0: 1.0, 160.0: 1.0}
_RATIO_EFFICIENCY = {50.0: 0.80, 80.0: 0.78, 100.0: 0.75, 120.0: 0.72, 160.0: 0.68}


def synthetic_catalog(n_motors: int = 100, n_gearboxes: int = 100, n_drives: int = 4, seed=0):
    """A large catalog of made-up, self-consistent parts for benchmarks and tests (every value
    ``source`` "synthetic"): ``n_motors`` 48 V motors with continuous torques log-uniform in
    0.02-5 N m and the other columns from scaling laws of the example catalog's motors;
    ``n_gearboxes`` strain-wave units of sizes log-uniform in 8-40 in the ratios 50, 80, 100,
    120, 160 (in turn), scaled from the example's size 25; ``n_drives`` drives of continuous
    currents log-uniform in 3-60 A. Values jittered by up to +-10 % (``seed``: numpy's
    default_rng). ``n_motors * n_gearboxes`` combinations per joint (100 x 100 = 10,000)."""
    import pandas as pd

    who = "synthetic_catalog"
    n_motors = _checks.integer(who, "n_motors", n_motors, lo=1, hi=10**6)
    n_gearboxes = _checks.integer(who, "n_gearboxes", n_gearboxes, lo=1, hi=10**6)
    n_drives = _checks.integer(who, "n_drives", n_drives, lo=0, hi=10**6)
    rng = np.random.default_rng(seed)
    motors = _synthetic_motors(rng, n_motors)
    gearboxes = _synthetic_gearboxes(rng, n_gearboxes)
    current = np.exp(rng.uniform(np.log(3.0), np.log(60.0), n_drives))
    drives = pd.DataFrame(
        {
            "name": [f"SD-{k:05d}" for k in range(n_drives)],
            "continuous_current": current,
            "peak_current": 3.0 * current,
            "bus_voltage": 48.0,
            "max_bus_voltage": 58.0,
            "bus_capacitance": 1e-4 * current,
            "braking_resistor_power": 5.0 * current,
            "braking_resistor_peak_power": 60.0 * current,
            "mass": 0.015 * current,
            "cost": 60.0 * current**0.6,
            "source": "synthetic",
        }
    )
    return Catalog.from_frames(motors, gearboxes, drives)


def _synthetic_motors(rng, n: int):
    import pandas as pd

    def jitter():
        return rng.uniform(0.9, 1.1, n)

    tc = np.exp(rng.uniform(np.log(0.02), np.log(5.0), n))
    kt = 0.14 * np.sqrt(tc) * jitter()
    loss = 15.0 * tc**0.8 * jitter()  # copper loss at the continuous torque, 25 degC [W]
    resistance = loss * kt**2 / tc**2
    t_max = 155.0
    r_total = (t_max - 25.0) / (loss * (1.0 + 0.00393 * (t_max - 25.0)))
    no_load = 48.0 / kt
    return pd.DataFrame(
        {
            "name": [f"SM-{k:05d}" for k in range(n)],
            "torque_constant": kt,
            "resistance": resistance,
            "rotor_inertia": 1.1e-4 * tc**1.6 * jitter(),
            "mass": 0.5 * tc**0.75 * jitter(),
            "continuous_torque": tc,
            "peak_torque": 3.1 * tc * jitter(),
            "no_load_speed": no_load,
            "max_speed": np.minimum(no_load, 1500.0),
            "voltage": 48.0,
            "thermal_resistance_winding": 0.3 * r_total,
            "thermal_resistance_housing": 0.7 * r_total,
            "thermal_time_constant_winding": 60.0 * tc**0.3 * jitter(),
            "thermal_time_constant_housing": 1500.0 * tc**0.3 * jitter(),
            "max_winding_temperature": t_max,
            "brake_torque": np.where(np.arange(n) % 3 == 2, 1.1 * tc, np.nan),
            "cost": 250.0 * tc**0.6 * jitter(),
            "source": "synthetic",
        }
    )


def _synthetic_gearboxes(rng, n: int):
    import pandas as pd

    def jitter():
        return rng.uniform(0.9, 1.1, n)

    s = np.exp(rng.uniform(np.log(8.0), np.log(40.0), n)) / 25.0  # size relative to 25
    ratio = np.array([_RATIOS[k % len(_RATIOS)] for k in range(n)])
    rated = 67.0 * s**3 * np.array([_RATIO_TORQUE[r] for r in ratio]) * jitter()
    rpm = 2.0 * np.pi / 60.0
    return pd.DataFrame(
        {
            "name": [f"SG-{k:05d}-{int(r)}" for k, r in enumerate(ratio)],
            "ratio": ratio,
            "efficiency": np.array([_RATIO_EFFICIENCY[r] for r in ratio])
            * rng.uniform(0.97, 1.03, n),
            "input_inertia": 4.13e-5 * s**5 * jitter(),
            "mass": 1.5 * s**2.3 * jitter(),
            "rated_torque": rated,
            "rated_input_speed": 2000.0 * rpm,
            "rated_life": 7000.0,
            "life_exponent": 3.0,
            "average_torque_limit": 1.6 * rated,
            "average_input_speed_limit": 3500.0 * rpm,
            "repeated_peak_torque": 2.35 * rated,
            "momentary_peak_torque": 4.3 * rated,
            "momentary_peak_count": 10000.0,
            "max_input_speed": 5600.0 * rpm * s**-0.6,
            "bearing_moment_allowable": 156.0 * s**3 * jitter(),
            "bearing_axial_allowable": 7200.0 * s**2 * jitter(),
            "bearing_radial_allowable": 4800.0 * s**2 * jitter(),
            "bearing_offset": 0.0145 * s,
            "bearing_dynamic_load_rating": 10400.0 * s**2 * jitter(),
            "bearing_pitch_diameter": 0.068 * s,
            "cost": 850.0 * s**1.5 * jitter(),
            "source": "synthetic",
        }
    )


# --- docs ---------------------------------------------------------------------------------------


def column_table(kind: str) -> str:
    """The Markdown table of a kind's columns (docs/api.md's "Catalogs" tables)."""
    _checks.choice("column_table", "kind", kind, KINDS)
    lines = ["| column | unit | required | allowed | meaning |", "|---|---|---|---|---|"]
    for c in COLUMNS[kind]:
        allowed = c.allowed + (f", default {c.default:g}" if c.default is not None else "")
        unit = c.unit or "text"
        lines.append(
            f"| `{c.name}` | {unit} | {'yes' if c.required else ''} | {allowed} | {c.doc} |"
        )
    return "\n".join(lines)
