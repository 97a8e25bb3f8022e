# SPDX-License-Identifier: GPL-2.0-or-later
"""Texture and gradation arithmetic (sediment.lab.texture) against closed forms and the USDA triangle."""
from __future__ import annotations

import math

import numpy as np
import pytest

from sediment.lab import texture

# a curve linear in log d from 0 % at 0.5 um to 100 % at 2 mm: the percent finer than d is
# 100 ln(d / 0.5 um) / ln(4000)
D = np.geomspace(0.5e-6, 2e-3, 61)
P = 100 * np.log(D / 0.5e-6) / math.log(4000)


def loglinear(d: float) -> float:
    return 100 * math.log(d / 0.5e-6) / math.log(4000)


def test_fractions_of_a_log_linear_curve():
    usda = texture.fractions(D, P, "USDA")
    assert usda["clay"] == pytest.approx(loglinear(2e-6))
    assert usda["silt"] == pytest.approx(loglinear(50e-6) - loglinear(2e-6))
    assert usda["sand"] == pytest.approx(100 - loglinear(50e-6))
    iso = texture.fractions(D, P, "ISO 14688-1")
    assert iso["silt"] == pytest.approx(loglinear(63e-6) - loglinear(2e-6))
    assert iso["gravel"] == pytest.approx(0.0)
    assert sum(iso.values()) == pytest.approx(100.0)


def test_usda_texture_is_of_the_fine_earth_and_iso_counts_the_gravel():
    d = np.array([1e-6, 2e-6, 50e-6, 2e-3, 10e-3])
    p = np.array([0.0, 20.0, 50.0, 80.0, 100.0])
    usda = texture.fractions(d, p, "USDA")
    assert [float(usda[k]) for k in ("clay", "silt", "sand")] == pytest.approx([25.0, 37.5, 37.5])
    iso = texture.fractions(d, p, "ISO 14688-1")
    assert iso["gravel"] == pytest.approx(20.0) and iso["clay"] == pytest.approx(20.0)


def test_outside_the_curve_a_fraction_is_known_only_where_the_curve_reaches_0_or_100():
    short = texture.fractions(np.array([5e-6, 100e-6]), np.array([30.0, 100.0]), "USDA")
    assert np.isnan(short["clay"]) and np.isnan(short["silt"]) and short["sand"] == pytest.approx(
        100 - (30 + 70 * math.log(10) / math.log(20)))
    open_top = texture.fractions(np.array([0.1e-6, 100e-6]), np.array([0.0, 90.0]), "ISO 14688-1")
    assert np.isnan(open_top["sand"]) and np.isnan(open_top["gravel"]) and np.isfinite(open_top["clay"])


@pytest.mark.parametrize("clay, silt, sand, name", [
    (3, 4, 93, "sand"), (5, 15, 80, "loamy sand"), (10, 25, 65, "sandy loam"), (20, 40, 40, "loam"),
    (15, 65, 20, "silt loam"), (5, 90, 5, "silt"), (27, 13, 60, "sandy clay loam"), (33, 34, 33, "clay loam"),
    (33, 57, 10, "silty clay loam"), (42, 8, 50, "sandy clay"), (45, 47, 8, "silty clay"), (60, 20, 20, "clay"),
])
def test_each_usda_class_at_a_point_inside_it(clay, silt, sand, name):
    assert texture.usda_class(clay, silt, sand) == name
    assert texture.usda_class(clay / 100, silt / 100, sand / 100) == name    # fractions are normalised


def test_every_point_of_the_triangle_has_exactly_one_class_and_nan_has_none():
    clay, silt = np.meshgrid(np.arange(0, 100.01, 0.5), np.arange(0, 100.01, 0.5))
    inside = clay + silt <= 100
    names = texture.usda_class(clay[inside], silt[inside], 100 - clay[inside] - silt[inside])
    assert set(names) == set(texture.USDA_CLASSES)
    assert texture.usda_class(np.nan, 10, 10) == ""


def test_characteristic_diameters_and_coefficients_of_a_log_linear_curve():
    d = texture.characteristic_diameters(D, P)
    for level in texture.LEVELS:
        assert d[f"D{level}"] == pytest.approx(0.5e-6 * 4000 ** (level / 100), rel=1e-9)
    cu, cc = texture.coefficients(d["D10"], d["D30"], d["D60"])
    assert cu == pytest.approx(4000 ** 0.5) and cc == pytest.approx(4000 ** (0.6 - 0.7))
    short = texture.characteristic_diameters(np.array([5e-6, 50e-6]), np.array([20.0, 100.0]))
    assert np.isnan(short["D10"]) and np.isfinite(short["D30"])


def test_bands_come_from_the_draws_and_the_report_writes_its_files(tmp_path):
    shifts = np.linspace(-2.0, 2.0, 41)
    draws = np.clip(P[None, :] + shifts[:, None] * np.sin(np.pi * P / 100)[None, :], 0, 100)
    report = texture.texture_report(D, P, draws)
    clay = texture.fractions(D, draws, "USDA")["clay"]
    rows = {(r[0], r[1]): r for r in report.texture_table().rows}
    low, high = np.percentile(clay, [2.5, 97.5])
    assert float(rows[("USDA", "clay")][3]) == pytest.approx(low, rel=1e-3)
    assert float(rows[("USDA", "clay")][4]) == pytest.approx(high, rel=1e-3)
    assert report.usda == "loam" and report.texture_table().rows[7][:2] == ["USDA class", "loam"]
    assert sum(report.class_share.values()) == pytest.approx(100.0)
    written = report.save(tmp_path)
    assert [p.name for p in written] == ["texture.csv", "gradation.csv", "texture.png"]
    assert (tmp_path / "texture.csv").read_text().splitlines()[0] == "system,fraction,percent,low,high"
    gradation = (tmp_path / "gradation.csv").read_text().splitlines()
    assert gradation[0] == "quantity,value,low,high,unit,reached" and gradation[1].startswith("D10,")
    figure = texture.gradation_figure(tmp_path / "gradation.png", D, P, P - 1, P + 1,
                                      (np.array([75e-6, 2e-3]), np.array([70.0, 100.0])),
                                      [("standard reduction", np.array([5e-6, 20e-6]), np.array([30.0, 50.0]))])
    assert figure.stat().st_size > 10000 and (tmp_path / "texture.png").stat().st_size > 10000
