"""Opening a USD stage: the file's size checked first, USD's own errors turned into one line
naming the file, and the stage's axes and unit.

USD reports a problem as a ``Tf.ErrorException`` whose text is a list of C++ locations ("Error
in 'pxrInternal_…::Sdf_CrateFile::…' at line 3546 in file …/crateFile.cpp : 'Sdf crate file
version mismatch …'"): only the quoted reasons mean anything to a user, so only they are kept.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from studio.core.files.budgets import FILE_BYTES
from studio.core.files.errors import MeshError

Array = np.ndarray
_REASON = re.compile(r" : '(.*?)'\s*(?=\n\s*Error in |\Z)", re.DOTALL)
REASON_CHARS = 300  # a reason quoting a whole line of a damaged file is cut here
# Z up to Y up, the front kept in front: USD's (and Blender's) Z-up faces look down -Y, and
# turning +Z to +Y takes -Y to +Z, the studio's front.
_Z_UP = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])
_UNITS = {1.0: "metres", 0.01: "centimetres", 0.001: "millimetres", 0.1: "decimetres",
          0.0254: "inches", 0.3048: "feet"}


def usd_reason(exc: BaseException) -> str:
    """The reasons in a USD error, without its C++ locations, one after the other."""
    reasons = [" ".join(r.split()) for r in _REASON.findall(str(exc)) if r.strip()]
    text = "; ".join(dict.fromkeys(reasons)) or " ".join(str(exc).split()) or type(exc).__name__
    return text if len(text) <= REASON_CHARS else text[:REASON_CHARS - 1] + "…"


def listen(path: Path):
    """A listener that keeps USD's warnings (a reference that cannot be found, a value of the
    wrong type) out of the terminal, for ``heard`` to say in the report; MeshError when
    usd-core is not installed."""
    try:
        from pxr import UsdUtils
    except ImportError:  # pragma: no cover - usd-core is a dependency
        raise MeshError("cannot read USD files: usd-core is not installed "
                        "(pip install usd-core)", path) from None
    return UsdUtils.CoalescingDiagnosticDelegate()


def heard(listener) -> str | None:
    """The report's line on what USD warned about while the stage was read, None if nothing."""
    said = [" ".join(str(d.commentary).split()) for d in listener.TakeUncoalescedDiagnostics()]
    said = [re.sub(r" \(instantiating stage on stage @.*?\)$", "", s) for s in said if s]
    if not said:
        return None
    text = "; ".join(dict.fromkeys(said))
    text = text if len(text) <= REASON_CHARS else text[:REASON_CHARS - 1] + "…"
    return f"USD warned: {text}"


def open_stage(path: Path):
    """The stage of a USD file (a ``.usdz`` package too), all of it loaded; MeshError naming
    the file when it is missing, over the file budget, or not a stage USD can read."""
    if not path.is_file():
        raise MeshError("no such file", path)
    FILE_BYTES.check(path.stat().st_size, "the USD file", path, MeshError)
    if path.stat().st_size == 0:
        raise MeshError("the file is empty", path)
    from pxr import Tf, Usd

    try:
        stage = Usd.Stage.Open(str(path), Usd.Stage.LoadAll)
    except Tf.ErrorException as exc:
        raise MeshError(f"cannot read the USD file ({usd_reason(exc)})", path) from None
    if stage is None:
        raise MeshError("cannot read the USD file", path)
    return stage


@dataclass(frozen=True)
class StageFrame:
    """How the stage's space turns into the studio's, and what to say about it."""

    to_studio: Array  # (3, 3): the stage's axes onto the studio's (Y up)
    up: str  # "Y" or "Z", the stage's upAxis
    authored: bool  # the stage says its up axis (else USD's default, Y, is assumed)
    meters_per_unit: float

    def line(self) -> str:
        """The report's line on units and axes."""
        unit = self.meters_per_unit
        name = _UNITS.get(round(unit, 6), f"{unit:g} m")
        axes = (f"the stage's upAxis {self.up}" if self.authored
                else "no upAxis in the stage: Y, USD's default")
        turned = ", turned to Y up" if self.up == "Z" else ""
        return f"units: the stage's ({name}, metersPerUnit {unit:g}); axes: {axes}{turned}"


def stage_frame(stage, path: Path) -> StageFrame:
    """The stage's up axis and unit (``upAxis``, ``metersPerUnit``), refused when damaged."""
    from pxr import UsdGeom

    up = str(UsdGeom.GetStageUpAxis(stage))
    unit = float(UsdGeom.GetStageMetersPerUnit(stage))
    if up not in ("Y", "Z"):
        raise MeshError(f"the stage's upAxis is '{up}': USD allows Y or Z", path)
    if not (np.isfinite(unit) and unit > 0):
        raise MeshError(f"the stage's metersPerUnit is {unit:g}: it must be a positive number",
                        path)
    return StageFrame(_Z_UP if up == "Z" else np.eye(3), up,
                      stage.HasAuthoredMetadata("upAxis"), unit)
