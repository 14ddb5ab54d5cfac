"""A block's perturbation: one record per kind, with all that kind's knowledge.

Each kind is a frozen dataclass whose fields are its parameters, each with its range and unit
(``Param``), checked in ``__post_init__``: a perturbation that exists is a valid one. The record also
says how a protocol file writes it (``as_dict``: ``perturbation = "curl"`` and its keys) and reads it
(``read``), how a person reads it (``label``), what its opposite is (a mixed block's ``opposite``
trials), and what it does: the loads on the arm (``loads``) and the transform of the shown hand
(``display``). A new kind is one class here and its line in ``KINDS``.

The kinds (each class's docstring has its parameters, units and TOML names): ``none`` (``Perturbation``
itself, ``NONE``), the force fields ``curl``, ``constant``, ``spring``, ``viscous`` and
``joint_viscous``, and the visual transforms ``rotation``, ``mirror`` and ``jointspace``.

Visual transforms change the hand AS SHOWN AND SCORED: the task tests the transformed hand
against home and the targets, and the metrics measure it, as in the experiments, where the
subject sees only a cursor. Each transform is ``show(x, y, q1, q2) -> (x', y')`` on floats.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, fields, replace
from typing import TYPE_CHECKING, Any, ClassVar, NamedTuple

from ..errors import UserError
from ..valid import check_float
from ..words import unknown_name

if TYPE_CHECKING:  # the physics (and numpy) are imported when a run builds its loads, not with a protocol
    from ..physics.loads import Loads

Display = Callable[[float, float, float, float], tuple[float, float]]
Matrix = tuple[tuple[float, float], tuple[float, float]]

#: The most a viscous (N s/m) or joint (N m s/rad) matrix may feed the arm (``feeding``): 0.85 of the largest that
#: held whole episodes under the pump, rounded down (``benchmarks/results/center_out_fields.json``, "feeding").
VISCOUS_MAX_FEEDING = 2.0
JOINT_MAX_FEEDING = 0.15


class ProtocolError(UserError, ValueError):
    """A protocol or perturbation that cannot be run, in one line naming the value as a protocol file names it."""


class Param(NamedTuple):
    """A kind's parameter: its name (its key in a protocol file), range, default and unit."""

    name: str
    low: float
    high: float
    default: float
    unit: str


def _param(low: float, high: float, unit: str, default: float = 0.0) -> Any:
    """A parameter's dataclass field: its default, and its range and unit for ``Perturbation.parameters``."""
    return field(default=default, metadata={"range": (low, high), "unit": unit})


@dataclass(frozen=True)
class Perturbation:
    """The kind ``none``: nothing changes. Every other kind is a subclass, registered in ``KINDS``."""

    kind: ClassVar[str] = "none"
    #: A force on the arm (the learning curve plots the perpendicular error), or a changed display.
    is_force: ClassVar[bool] = False
    is_visual: ClassVar[bool] = False
    #: A field ``F = B v``: a channel trial's adaptation index is measured against one of these.
    is_velocity_field: ClassVar[bool] = False
    #: Whether it has an opposite (every parameter negated): a field or a rotation. Only these can be mixed.
    has_opposite: ClassVar[bool] = False

    def __post_init__(self) -> None:
        for p in self.parameters():
            try:
                value = check_float(self.file_key(p.name), getattr(self, p.name), p.low, p.high)
            except ValueError as exc:
                raise ProtocolError(str(exc)) from None
            object.__setattr__(self, p.name, value)

    @classmethod
    @functools.cache
    def parameters(cls) -> tuple[Param, ...]:
        return tuple(Param(f.name, *f.metadata["range"], f.default, f.metadata["unit"]) for f in fields(cls))

    @classmethod
    def file_key(cls, name: str) -> str:
        """How a protocol file names the parameter ``name`` (and so the messages that refuse it)."""
        return name

    @staticmethod
    def make(kind: str, **values: float) -> Perturbation:
        """The perturbation ``kind`` (a protocol file's name for it) with these parameters, the rest at their
        defaults."""
        cls = KINDS.get(kind)
        if cls is None:
            raise ProtocolError(unknown_name("perturbation", kind, KINDS))
        extra = values.keys() - {p.name for p in cls.parameters()}
        if extra:
            raise ProtocolError(f"perturbation {kind} has no parameter {', '.join(sorted(extra))}")
        return cls(**values)

    # ------------------------------------------------------------- a protocol file's words
    @classmethod
    def file_keys(cls) -> frozenset[str]:
        """Its keys in a protocol file's block, besides ``perturbation``."""
        return frozenset(p.name for p in cls.parameters())

    @classmethod
    def read(cls, table: Mapping[str, object]) -> Perturbation:
        """This kind from a protocol file's block (whose keys the caller has checked): each parameter given, the
        rest at their defaults. Raises ``ProtocolError`` naming the key; the caller adds where the block is."""
        return cls(**{p.name: table[p.name] for p in cls.parameters() if p.name in table})

    def as_dict(self) -> dict[str, object]:
        """As a protocol file writes it in its block."""
        return {"perturbation": self.kind, **dict(self.items())}

    def label(self) -> str:
        """e.g. ``curl b=2 N s/m``; ``none`` for none."""
        units = {p.name: p.unit for p in self.parameters()}
        return " ".join([self.kind, *(f"{name}={value:g} {units[name]}" for name, value in self.items())])

    # ------------------------------------------------------------- its values
    def items(self) -> tuple[tuple[str, float], ...]:
        """Its parameters' (name, value), in order."""
        return tuple((p.name, getattr(self, p.name)) for p in self.parameters())

    def __getitem__(self, name: str) -> float:
        return dict(self.items())[name]

    @property
    def is_null(self) -> bool:
        """Whether it changes nothing: ``none``, or a field or rotation of size zero (curl ``b = 0``, a zero
        matrix, no force, no stiffness, ``angle = 0``). A mirror or a joint-space display always changes
        the display."""
        return all(value == 0.0 for _name, value in self.items())

    def opposite(self) -> Perturbation:
        """Every parameter negated: the opposite field or rotation (a mixed block's ``opposite`` trials)."""
        if not self.has_opposite:
            raise ProtocolError(f"perturbation {self.kind} has no opposite")
        return replace(self, **{name: -value for name, value in self.items()})

    @property
    def matrix(self) -> Matrix | None:
        """``B`` of a velocity field at the hand ``F = B v`` (curl or viscous), else None."""
        return None

    @property
    def joint_matrix(self) -> Matrix | None:
        """``W`` of a joint-space field ``tau = W qdot`` (``joint_viscous``), else None."""
        return None

    # ------------------------------------------------------------- what it does
    def loads(self, home: tuple[float, float]) -> Loads | None:
        """The hand force (or joint torque) of a force field; None when the arm's own dynamics run."""
        return None

    def display(self, home: tuple[float, float], home_q: tuple[float, float]) -> Display | None:
        """The transform of the shown hand, or None for the hand as it is."""
        return None


NONE = Perturbation()


@dataclass(frozen=True)
class Curl(Perturbation):
    """``curl`` (``b``, N s/m): the force field ``F = b [[0, 1], [-1, 0]] v`` at the hand; ``b > 0`` pushes
    clockwise of the hand's motion. It does no work: the force is across the hand's velocity."""

    kind: ClassVar[str] = "curl"
    is_force: ClassVar[bool] = True
    is_velocity_field: ClassVar[bool] = True
    has_opposite: ClassVar[bool] = True
    b: float = _param(-50.0, 50.0, "N s/m")

    @property
    def matrix(self) -> Matrix:
        return (0.0, self.b), (-self.b, 0.0)

    def loads(self, home: tuple[float, float]) -> Loads | None:
        from ..physics.loads import CurlField, Loads

        return Loads(hand=CurlField(self.b)) if self.b != 0.0 else None


@dataclass(frozen=True)
class Constant(Perturbation):
    """``constant`` (``fx``, ``fy``, N): a steady force at the hand."""

    kind: ClassVar[str] = "constant"
    is_force: ClassVar[bool] = True
    has_opposite: ClassVar[bool] = True
    fx: float = _param(-20.0, 20.0, "N")
    fy: float = _param(-20.0, 20.0, "N")

    def loads(self, home: tuple[float, float]) -> Loads | None:
        from ..physics.loads import ConstantForce, Loads

        return Loads(hand=ConstantForce(self.fx, self.fy)) if (self.fx, self.fy) != (0.0, 0.0) else None


@dataclass(frozen=True)
class Spring(Perturbation):
    """``spring`` (``stiffness``, N/m): a spring from the hand to the home position."""

    kind: ClassVar[str] = "spring"
    is_force: ClassVar[bool] = True
    stiffness: float = _param(0.0, 250.0, "N/m")

    def loads(self, home: tuple[float, float]) -> Loads | None:
        from ..physics.loads import Loads, SpringField

        return Loads(hand=SpringField(self.stiffness, home)) if self.stiffness != 0.0 else None


def feeding(matrix: Matrix) -> float:
    """The most energy a velocity field ``F = M v`` (or ``tau = M qdot``) feeds the arm per squared speed: the sum of
    the positive eigenvalues of ``M``'s symmetric part, which alone does work (``v . M v``; the antisymmetric part,
    a curl, pushes across the motion). Where only one eigenvalue is positive (the viscous preset's, 1.99 and -1.86
    N s/m) it is the largest eigenvalue; where both are, they add up: the largest eigenvalue alone does not bound
    what the arm takes, since twice the identity (both 2 N s/m) runs away under the pump where every shape that
    feeds 2.4 in all holds (``benchmarks/center_out_fields.py``)."""
    (a, b), (c, d) = matrix
    mean, radius = (a + d) / 2, math.hypot((a - d) / 2, (b + c) / 2)
    return max(mean + radius, 0.0) + max(mean - radius, 0.0)


@dataclass(frozen=True)
class _MatrixField(Perturbation):
    """A field given by a 2 x 2 matrix, its four entries the parameters, row by row: a protocol file writes it
    ``matrix = [[.., ..], [.., ..]]`` and names an entry ``matrix[i][j]``.

    Each entry has its range, and the matrix as a whole feeds the arm at most ``max_feeding`` (``feeding``): more
    outweighs the joints' own damping and a reach runs away, which the entries' ranges alone allowed (issue 52). The
    limit is measured by ``benchmarks/center_out_fields.py`` (its pump policy, with a margin), and
    ``tests/test_env_fields_protocol.py`` holds it to the committed measurement."""

    #: The matrix's letter in the label, and its entries' format there.
    symbol: ClassVar[str]
    number_format: ClassVar[str]
    #: The most its symmetric part's positive eigenvalues may sum to, in the entries' unit.
    max_feeding: ClassVar[float]
    is_force: ClassVar[bool] = True
    is_velocity_field: ClassVar[bool] = True
    has_opposite: ClassVar[bool] = True

    def __post_init__(self) -> None:
        super().__post_init__()
        fed = feeding(self.entries)
        if fed > self.max_feeding + 1e-12:  # the eigenvalues' round-off: a matrix at the limit is within it
            unit = self.parameters()[0].unit
            raise ProtocolError(f"matrix: a {self.kind} field may feed the arm at most {self.max_feeding:g} {unit} "
                                f"(its symmetric part's positive eigenvalues summed; more runs a reach away), "
                                f"this one feeds {fed:.3g}")

    @classmethod
    def from_matrix(cls, matrix: Matrix) -> _MatrixField:
        (a, b), (c, d) = matrix
        return cls(a, b, c, d)

    @property
    def entries(self) -> Matrix:
        a, b, c, d = (value for _name, value in self.items())
        return (a, b), (c, d)

    @classmethod
    def file_key(cls, name: str) -> str:
        k = [p.name for p in cls.parameters()].index(name)
        return f"matrix[{k // 2}][{k % 2}]"

    @classmethod
    def file_keys(cls) -> frozenset[str]:
        return frozenset({"matrix"})

    @classmethod
    def read(cls, table: Mapping[str, object]) -> Perturbation:
        if "matrix" not in table:
            return cls()
        value = table["matrix"]
        if not (isinstance(value, list) and len(value) == 2
                and all(isinstance(row, list) and len(row) == 2 for row in value)):
            names = [p.name for p in cls.parameters()]
            raise ProtocolError(f"matrix must be [[{names[0]}, {names[1]}], [{names[2]}, {names[3]}]] "
                                f"({cls.parameters()[0].unit})")
        return cls.from_matrix(value)  # type: ignore[arg-type]

    def as_dict(self) -> dict[str, object]:
        return {"perturbation": self.kind, "matrix": [list(row) for row in self.entries]}

    def label(self) -> str:
        (a, b), (c, d) = self.entries
        f = self.number_format
        return (f"{self.kind} {self.symbol}=[[{a:{f}}, {b:{f}}], [{c:{f}}, {d:{f}}]] "
                f"{self.parameters()[0].unit}")


@dataclass(frozen=True)
class Viscous(_MatrixField):
    """``viscous`` (``matrix = [[b11, b12], [b21, b22]]``, N s/m): the field ``F = B v`` at the hand with a full
    matrix, as Shadmehr & Mussa-Ivaldi (1994) used; its symmetric part does work on the arm."""

    kind: ClassVar[str] = "viscous"
    symbol: ClassVar[str] = "B"
    number_format: ClassVar[str] = "g"
    max_feeding: ClassVar[float] = VISCOUS_MAX_FEEDING
    b11: float = _param(-50.0, 50.0, "N s/m")
    b12: float = _param(-50.0, 50.0, "N s/m")
    b21: float = _param(-50.0, 50.0, "N s/m")
    b22: float = _param(-50.0, 50.0, "N s/m")

    @property
    def matrix(self) -> Matrix:
        return self.entries

    def loads(self, home: tuple[float, float]) -> Loads | None:
        from ..physics.loads import Loads, ViscousField

        return None if self.is_null else Loads(hand=ViscousField(self.entries))


@dataclass(frozen=True)
class JointViscous(_MatrixField):
    """``joint_viscous`` (``matrix = [[w11, w12], [w21, w22]]``, N m s/rad): a viscous field in joint coordinates,
    the torque ``tau = W qdot`` at the joints whatever the posture (issue 41: Shadmehr & Mussa-Ivaldi's test of
    the frame a field is learned in). Seen at the hand it is ``J^-T W J^-1``, which changes with the posture,
    where a hand field ``B`` stays ``B``."""

    kind: ClassVar[str] = "joint_viscous"
    symbol: ClassVar[str] = "W"
    number_format: ClassVar[str] = ".4g"
    max_feeding: ClassVar[float] = JOINT_MAX_FEEDING
    w11: float = _param(-5.0, 5.0, "N m s/rad")
    w12: float = _param(-5.0, 5.0, "N m s/rad")
    w21: float = _param(-5.0, 5.0, "N m s/rad")
    w22: float = _param(-5.0, 5.0, "N m s/rad")

    @property
    def joint_matrix(self) -> Matrix:
        return self.entries

    def loads(self, home: tuple[float, float]) -> Loads | None:
        from ..physics.loads import JointLoad, Loads

        return None if self.is_null else Loads(joint=JointLoad(viscosity=self.entries))


@dataclass(frozen=True)
class Rotation(Perturbation):
    """``rotation`` (``angle``, degrees): the hand is shown, and scored, rotated about home, counter-clockwise for
    ``angle > 0``."""

    kind: ClassVar[str] = "rotation"
    is_visual: ClassVar[bool] = True
    has_opposite: ClassVar[bool] = True
    angle: float = _param(-180.0, 180.0, "deg")

    def display(self, home: tuple[float, float], home_q: tuple[float, float]) -> Display | None:
        return rotation(self.angle, home) if self.angle != 0.0 else None


@dataclass(frozen=True)
class Mirror(Perturbation):
    """``mirror`` (``axis``, degrees): the hand is shown mirrored in the line through home at that angle from +x
    (90: left and right swap)."""

    kind: ClassVar[str] = "mirror"
    is_visual: ClassVar[bool] = True
    axis: float = _param(-180.0, 180.0, "deg", default=90.0)

    @property
    def is_null(self) -> bool:
        return False

    def display(self, home: tuple[float, float], home_q: tuple[float, float]) -> Display | None:
        return mirror(self.axis, home)


@dataclass(frozen=True)
class JointSpace(Perturbation):
    """``jointspace`` (``gain``, m/rad): Flanagan & Rao's display: the hand is shown at
    ``home + gain (q1 - q1_home, q2 - q2_home)``, shoulder angle across, elbow angle up."""

    kind: ClassVar[str] = "jointspace"
    is_visual: ClassVar[bool] = True
    gain: float = _param(0.01, 2.0, "m/rad", default=0.25)

    @property
    def is_null(self) -> bool:
        return False

    def display(self, home: tuple[float, float], home_q: tuple[float, float]) -> Display | None:
        return joint_space(self.gain, home, home_q)


#: Every kind by its name in a protocol file, in the order the docs and messages list them.
KINDS: dict[str, type[Perturbation]] = {k.kind: k for k in (Perturbation, Curl, Constant, Spring, Viscous,
                                                             JointViscous, Rotation, Mirror, JointSpace)}


# ----------------------------------------------------------------- the transforms of the shown hand
def rotation(angle_deg: float, centre: tuple[float, float]) -> Display:
    c, s = math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))
    cx, cy = centre

    def show(x: float, y: float, q1: float, q2: float) -> tuple[float, float]:
        dx, dy = x - cx, y - cy
        return cx + c * dx - s * dy, cy + s * dx + c * dy

    # Its numbers, for the browser's lab (``lab.plan``): (cx + m11 dx) + m12 dy, (cy + m21 dx) + m22 dy is the same
    # arithmetic, a - b being a + (-b) in IEEE doubles.
    show.plan = ("linear", cx, cy, c, -s, s, c)  # type: ignore[attr-defined]
    return show


def mirror(axis_deg: float, centre: tuple[float, float]) -> Display:
    # Reflection in the line through the centre with direction (cos a, sin a): the matrix [[cos 2a, sin 2a],
    # [sin 2a, -cos 2a]].
    c, s = math.cos(2.0 * math.radians(axis_deg)), math.sin(2.0 * math.radians(axis_deg))
    cx, cy = centre

    def show(x: float, y: float, q1: float, q2: float) -> tuple[float, float]:
        dx, dy = x - cx, y - cy
        return cx + c * dx + s * dy, cy + s * dx - c * dy

    show.plan = ("linear", cx, cy, c, s, s, -c)  # type: ignore[attr-defined]
    return show


def joint_space(gain: float, centre: tuple[float, float], home_q: tuple[float, float]) -> Display:
    cx, cy = centre
    h1, h2 = home_q

    def show(x: float, y: float, q1: float, q2: float) -> tuple[float, float]:
        return cx + gain * (q1 - h1), cy + gain * (q2 - h2)

    show.plan = ("joint", cx, cy, gain, h1, h2)  # type: ignore[attr-defined]
    return show


def across_path_deg(hand: Sequence[Sequence[float]]) -> float:
    """The direction (deg, 0 to 90) of the first of four, 90 deg apart, in which the hand field ``F = B v`` pushes a
    reach along its path only by ``tr B / 2`` (``u . B u`` for the unit direction ``u``): 45 deg from the principal
    axes of ``B``'s symmetric part, where the field pushes most across the path. 0 for a field with no such axes (a
    curl, or the same push along every direction). Plain math, no numpy: the presets import it (``armgame --help``
    loads them and no heavy package)."""
    a, c = 0.5 * (hand[0][0] - hand[1][1]), 0.5 * (hand[0][1] + hand[1][0])
    if math.hypot(a, c) < 1e-12:
        return 0.0
    # u . B u = tr B / 2 + a cos 2t + c sin 2t, which is tr B / 2 where a cos 2t + c sin 2t = 0.
    return math.degrees(0.5 * math.atan2(-a, c)) % 90.0
