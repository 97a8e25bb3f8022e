# SPDX-License-Identifier: GPL-2.0-or-later
"""The physics against measurements: the drag laws against Roos & Willmarth's (1971) measured drag of
spheres, water at the laboratory's temperature, and what the hindrances refuse (docs/physics.md)."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from sediment import _core

DATA = Path(__file__).resolve().parents[1] / "data"


def measured_drag() -> tuple[np.ndarray, np.ndarray]:
    re, cd = np.loadtxt(DATA / "roos_willmarth_1971_spheres.csv", delimiter=",", comments="#", skiprows=4, unpack=True)
    return re, cd


def deviations(law: str) -> np.ndarray:
    re, cd = measured_drag()
    return np.array([_core.drag_coefficient(law, r) for r in re]) / cd - 1


def data_scatter() -> float:
    """Root-mean-square deviation of each measurement from the median of the others within a tenth of a
    decade of its Reynolds number: how far the measurements themselves spread."""
    re, cd = measured_drag()
    spread = []
    for k in range(len(re)):
        near = (np.abs(np.log10(re / re[k])) < 0.1) & (np.arange(len(re)) != k)
        if near.sum() >= 3:
            spread.append(cd[k] / np.median(cd[near]) - 1)
    return float(np.sqrt(np.mean(np.square(spread))))


def test_standard_curve_follows_the_measured_drag_within_its_scatter():
    standard = deviations("standard")
    scatter = data_scatter()
    assert len(standard) == 122
    # The measurements spread by 5.0 % (rms) about their local median; the curve's median deviation from
    # them is 2.8 %, its mean -2.6 % and its rms 6.5 % (outliers such as Cd 0.39 at Re 6210 and 0.49 at 8700).
    assert np.median(np.abs(standard)) < min(scatter, 0.035)
    assert abs(np.mean(standard)) < 0.03
    assert np.sqrt(np.mean(standard ** 2)) < 0.07
    # Dallavalle's curve, the paper's, is 16 % off at the median over these Reynolds numbers.
    assert np.median(np.abs(deviations("dallavalle"))) > 0.1
    assert np.median(np.abs(standard)) < np.median(np.abs(deviations("schiller-naumann")))


def test_water_at_the_laboratory_temperature():
    assert _core.water_density(20.0) == pytest.approx(998.2067, abs=1e-3)
    assert _core.water_viscosity(20.0) == pytest.approx(1.0016e-3, rel=1e-12)
    assert _core.water_viscosity(4.0) == pytest.approx(1.5673e-3, rel=1e-3)
    assert _core.water_viscosity(40.0) == pytest.approx(0.6527e-3, rel=1e-3)
    for bad in (-1.0, 40.5, float("nan")):
        with pytest.raises(ValueError, match="0-40 C"):
            _core.water_viscosity(bad)


@pytest.mark.parametrize("law, hindrance, message", [
    ("schiller-naumann", "richardson-zaki", "does not take hindrance"),
    ("zhang-li", "difelice", "does not take hindrance"),
    ("difelice", "garside", "does not take hindrance"),
    ("standard", "rz", "unknown hindrance 'rz'"),
])
def test_hindrance_refused_where_it_does_not_apply(law, hindrance, message):
    with pytest.raises(ValueError, match=message):
        _core.DragModel(law, 998.2, 1.002e-3, hindrance=hindrance)


def test_the_package_exports_what_the_core_has():
    import sediment

    assert sediment.water_viscosity(20.0) == pytest.approx(1.0016e-3)
    for name in sediment.__all__:
        assert callable(getattr(sediment, name)), name
    # dir() and completion show what a user calls and the version, nothing of the module's workings
    assert dir(sediment) == sorted(sediment.__all__ + ["__version__"])
    assert {"DragModel", "stokes_velocity", "lammps_with_styles"} <= set(dir(sediment))


def test_the_api_page_documents_every_name_of_the_package():
    """docs/site/api.rst lists every name `import sediment` gives (DragModel, stokes_velocity, ...)."""
    import sediment

    page = (Path(__file__).resolve().parents[2] / "docs" / "site" / "api.rst").read_text()
    block = page.split(".. automodule:: sediment\n", 1)[1]
    members = block.split(":members:", 1)[1].splitlines()[0]
    assert sorted(m.strip() for m in members.split(",")) == sorted(sediment.__all__)
