# SPDX-License-Identifier: GPL-2.0-or-later
"""Texture and gradation arithmetic (sediment.lab.texture) against closed forms and the USDA triangle."""
from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from sediment.lab import texture

# a curve linear in log d from 0 % at 0.5 um to 100 % at 2 mm: P(d) = 100 ln(d / 0.5 um) / ln(4000)
D = np.geomspace(0.5e-6, 2e-3, 61)
U = np.log(D / 0.5e-6) / math.log(4000)    # 0 .. 1 along the curve
P = 100 * U
LN = math.log(4000)
SHIFTS = np.linspace(-2.0, 2.0, 401)       # the draws' vertical shifts [points]; 2.5 / 97.5 % fall on -1.9 / 1.9


def loglinear(d: float) -> float:
    return 100 * math.log(d / 0.5e-6) / LN


def test_fractions_of_a_log_linear_curve_by_hand():
    usda = texture.fractions(D, P, "USDA")
    assert float(usda["clay"]) == pytest.approx(100 * math.log(4) / LN)           # 0.5 -> 2 um
    assert float(usda["silt"]) == pytest.approx(100 * math.log(25) / LN)          # 2 -> 50 um
    assert float(usda["sand"]) == pytest.approx(100 * math.log(40) / LN)          # 50 um -> 2 mm
    iso = texture.fractions(D, P, "ISO 14688-1")
    assert float(iso["clay"]) == pytest.approx(100 * math.log(4) / LN)
    assert float(iso["silt"]) == pytest.approx(100 * math.log(31.5) / LN)         # 2 -> 63 um
    assert float(iso["sand"]) == pytest.approx(100 * math.log(2000 / 63) / LN)
    assert float(iso["gravel"]) == 0.0
    assert sum(float(v) for v in iso.values()) == pytest.approx(100.0)


def test_fractions_vectorise_over_draws():
    draws = np.stack([P, np.clip(P + 5, 0, 100), np.clip(P - 5, 0, 100)])
    for system in texture.SYSTEMS:
        many = texture.fractions(D, draws, system)
        for name, values in many.items():
            assert values.shape == (3,)
            assert values == pytest.approx([float(texture.fractions(D, row, system)[name]) for row in draws])


def test_usda_texture_is_of_the_fine_earth_and_iso_counts_the_gravel():
    d = np.array([1e-6, 2e-6, 50e-6, 2e-3, 10e-3])
    p = np.array([0.0, 20.0, 50.0, 80.0, 100.0])
    usda = texture.fractions(d, p, "USDA")
    assert [float(usda[k]) for k in ("clay", "silt", "sand")] == pytest.approx([25.0, 37.5, 37.5])    # of 80 %
    iso = texture.fractions(d, p, "ISO 14688-1")
    assert float(iso["gravel"]) == pytest.approx(20.0) and float(iso["clay"]) == pytest.approx(20.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")    # all gravel: no fine earth, NaN without a division warning
        gravel = texture.fractions(np.array([3e-3, 10e-3]), np.array([0.0, 100.0]), "USDA")
    assert all(np.isnan(v) for v in gravel.values())


def test_outside_the_curve_a_fraction_is_known_only_where_the_curve_is_closed():
    # starts at 30 % at 5 um: clay and silt are unknown; ends at 100 %: nothing coarser than 100 um
    short = texture.fractions(np.array([5e-6, 100e-6]), np.array([30.0, 100.0]), "USDA")
    assert np.isnan(short["clay"]) and np.isnan(short["silt"])
    assert float(short["sand"]) == pytest.approx(100 - (30 + 70 * math.log(10) / math.log(20)))
    iso = texture.fractions(np.array([5e-6, 100e-6]), np.array([30.0, 100.0]), "ISO 14688-1")
    assert float(iso["gravel"]) == 0.0 and np.isnan(iso["clay"])
    # ends at 90 % at 100 um: the sand and gravel are unknown, and with them the USDA fine earth
    open_top = np.array([0.1e-6, 100e-6]), np.array([0.0, 90.0])
    iso = texture.fractions(*open_top, "ISO 14688-1")
    assert np.isnan(iso["sand"]) and np.isnan(iso["gravel"])
    assert float(iso["clay"]) == pytest.approx(90 * math.log(20) / math.log(1000))
    assert all(np.isnan(v) for v in texture.fractions(*open_top, "USDA").values())
    # starts at 0 % at 5 um: no clay; reaches 100 % at 1 mm and stays there: no gravel
    closed = texture.fractions(np.array([5e-6, 1e-3, 5e-3]), np.array([0.0, 100.0, 100.0]), "ISO 14688-1")
    assert float(closed["clay"]) == 0.0 and float(closed["gravel"]) == 0.0
    assert sum(float(v) for v in closed.values()) == pytest.approx(100.0)
    assert texture.percent_at(np.array([5e-6, 1e-3]), np.array([0.0, 100.0]), [1e-6, 2e-3]) == pytest.approx([0, 100])


@pytest.mark.parametrize("clay, silt, sand, name", [
    (2, 5, 93, "sand"), (4, 16, 80, "loamy sand"), (10, 25, 65, "sandy loam"), (18, 40, 42, "loam"),
    (15, 65, 20, "silt loam"), (4, 88, 8, "silt"), (28, 12, 60, "sandy clay loam"), (33, 33, 34, "clay loam"),
    (33, 55, 12, "silty clay loam"), (42, 6, 52, "sandy clay"), (46, 48, 6, "silty clay"), (60, 20, 20, "clay"),
])
def test_each_usda_class_at_a_point_inside_it(clay, silt, sand, name):
    assert texture.usda_class(clay, silt, sand) == name
    assert texture.usda_class(clay / 100, silt / 100, sand / 100) == name                 # fractions of 1
    assert texture.usda_class(clay * 0.996, silt * 0.996, sand * 0.996) == name            # rounded percents


@pytest.mark.parametrize("clay, silt, sand, name", [
    (40, 40, 20, "silty clay"), (20, 28, 52, "loam"), (7, 41, 52, "loam"), (35, 20, 45, "clay loam"),
    (27, 28, 45, "clay loam"), (27, 53, 20, "silty clay loam"), (27, 50, 23, "clay loam"), (12, 80, 8, "silt loam"),
    (0, 80, 20, "silt"), (0, 50, 50, "silt loam"), (7, 50, 43, "silt loam"), (0, 15, 85, "loamy sand"),
    (10, 0, 90, "loamy sand"), (15, 0, 85, "sandy loam"), (0, 30, 70, "sandy loam"), (40, 15, 45, "clay"),
    (55, 0, 45, "clay"), (35, 0, 65, "sandy clay"), (20, 0, 80, "sandy clay loam"), (40, 60, 0, "silty clay"),
    (0, 0, 100, "sand"), (0, 100, 0, "silt"), (100, 0, 0, "clay"),
])
def test_usda_class_on_the_edges_follows_the_manuals_inequalities(clay, silt, sand, name):
    assert texture.usda_class(clay, silt, sand) == name


def test_every_point_of_the_triangle_has_exactly_one_class():
    clay, silt = np.meshgrid(np.arange(0, 100.01, 0.5), np.arange(0, 100.01, 0.5))
    inside = clay + silt <= 100
    clay, silt = clay[inside], silt[inside]
    rules = np.array(texture._usda_rules(clay, silt, 100 - clay - silt))
    assert np.all(rules.sum(axis=0) == 1), np.column_stack([clay, silt])[rules.sum(axis=0) != 1][:5]
    names = texture.usda_class(clay, silt, 100 - clay - silt)
    assert names.shape == clay.shape and set(names) == set(texture.USDA_CLASSES)
    assert np.all(names == np.array(texture.USDA_CLASSES)[rules.argmax(axis=0)])


def test_the_drawn_polygons_are_the_classes_and_tile_the_triangle():
    from matplotlib.path import Path as Outline

    areas = []
    for corners in texture.USDA_POLYGONS.values():
        c, s = np.array(corners, float).T
        areas.append(abs(np.sum(c * np.roll(s, -1) - np.roll(c, -1) * s)) / 2)
    assert sum(areas) == pytest.approx(5000.0) and min(areas) > 0    # the triangle's area in (clay, silt)
    points = np.random.default_rng(7).uniform(0, 100, (20000, 2))
    points = points[points.sum(axis=1) < 100]
    names = texture.usda_class(points[:, 0], points[:, 1], 100 - points.sum(axis=1))
    for name, corners in texture.USDA_POLYGONS.items():
        within = Outline(np.array(corners, float)).contains_points(points)
        assert within.any() and np.all(names[within] == name), name


def test_unknown_inputs_have_no_class_and_shapes_broadcast():
    assert texture.usda_class(np.nan, 10, 10) == "" and texture.usda_class(0, 0, 0) == ""
    assert texture.usda_class(-5, 50, 55) == ""
    assert texture.usda_class(-1e-12, 20, 80) == "loamy sand"    # rounding below 0 is 0
    names = texture.usda_class(np.array([[20.0], [60.0]]), 20.0, np.array([60.0, 20.0]))
    assert names.shape == (2, 2) and names[0, 0] == "sandy clay loam" and names[1, 1] == "clay"


def test_characteristic_diameters_and_coefficients_of_a_log_linear_curve():
    d = texture.characteristic_diameters(D, P)
    assert list(d) == ["D10", "D30", "D50", "D60"]
    for level in texture.LEVELS:
        assert float(d[f"D{level}"]) == pytest.approx(0.5e-6 * 4000 ** (level / 100), rel=1e-9)
    cu, cc = texture.coefficients(d["D10"], d["D30"], d["D60"])
    assert float(cu) == pytest.approx(4000 ** 0.5) and float(cc) == pytest.approx(4000 ** (0.6 - 0.7))
    draws = np.stack([P, np.clip(P + 10, 0, 100)])    # + 10 points: D shifts by 4000^(-0.1) in d
    many = texture.characteristic_diameters(D, draws, (30, 50))
    assert many["D30"].shape == (2,) and many["D50"][1] / many["D50"][0] == pytest.approx(4000 ** -0.1)


def test_a_level_the_curve_does_not_cross_has_no_diameter():
    short = texture.characteristic_diameters(np.array([5e-6, 50e-6]), np.array([20.0, 55.0]))
    assert np.isnan(short["D10"]) and np.isnan(short["D60"])              # starts above 10, stops below 60
    assert float(short["D30"]) == pytest.approx(5e-6 * 10 ** (10 / 35))
    exact = texture.characteristic_diameters(np.array([5e-6, 50e-6]), np.array([10.0, 55.0]), (10,))
    assert float(exact["D10"]) == pytest.approx(5e-6)                      # starts on the level
    cu, cc = texture.coefficients(short["D10"], short["D30"], short["D60"])
    assert np.isnan(cu) and np.isnan(cc)


def _shifted(start: float, rise: float) -> tuple[np.ndarray, np.ndarray]:
    """A log-linear curve from `start` % at 0.5 um rising by `rise` points to 2 mm, and its draws
    shifted by SHIFTS."""
    central = start + rise * U
    return central, central[None, :] + SHIFTS[:, None]


def test_bands_are_the_percentiles_of_the_draws_quantities():
    central, draws = _shifted(5.0, 90.0)
    report = texture.texture_report(D, central, draws)
    p2um = 5 + 90 * math.log(4) / LN
    rows = {(r[0], r[1]): r for r in report.texture_table().rows}
    assert [float(c) for c in rows[("ISO 14688-1", "clay")][2:]] == pytest.approx([p2um, p2um - 1.9, p2um + 1.9],
                                                                                  rel=1e-3)
    assert [float(c) for c in rows[("ISO 14688-1", "gravel")][2:]] == pytest.approx([5.0, 3.1, 6.9], rel=1e-3)
    silt = rows[("ISO 14688-1", "silt")]    # a vertical shift leaves the silt as it is: no spread
    assert silt[3] == silt[2] == silt[4]
    low, high = texture._band(report.fraction_draws["ISO 14688-1"]["clay"])
    assert (low, high) == pytest.approx((p2um - 1.9, p2um + 1.9), abs=1e-9)
    # D50 = 0.5 um 4000^((45 - shift) / 90): the highest shifts give the smallest D50
    low, high = texture._band(report.gradation_draws["D50"])
    assert (low, high) == pytest.approx((0.5e-6 * 4000 ** (43.1 / 90), 0.5e-6 * 4000 ** (46.9 / 90)), rel=1e-9)
    assert report.gradation["D50"] == pytest.approx(0.5e-6 * 4000 ** 0.5)
    cu_low, cu_high = texture._band(report.gradation_draws["Cu"])   # Cu = 4000^(50/90) whatever the shift
    assert cu_low == pytest.approx(4000 ** (50 / 90)) and cu_high == pytest.approx(4000 ** (50 / 90))
    assert report.usda == "loam" and report.class_share == {"loam": 100.0}


def test_a_band_over_part_of_the_draws_says_so():
    central, draws = _shifted(9.005, 85.99)    # shifts up to 0.99 reach 10 % within the curve: 300 of 401 draws
    report = texture.texture_report(D, central, draws)
    table = report.gradation_table()
    d10 = table.rows[0]
    assert d10[0] == "D10" and d10[4] == "um" and float(d10[5]) == pytest.approx(100 * 300 / 401, rel=1e-3)
    reaching = 0.5e-6 * 4000 ** ((10 - 9.005 - SHIFTS[SHIFTS < 0.995]) / 85.99)
    assert [float(c) for c in d10[2:4]] == pytest.approx(np.percentile(reaching * 1e6, [2.5, 97.5]), rel=1e-3)
    assert any(n.startswith("D10: the band is over the 74.8 %") for n in table.notes)


def test_save_writes_the_documented_layout(tmp_path):
    d = np.array([0.5e-6, 2e-6, 50e-6, 2e-3])
    loam, sandy_loam = np.array([0.0, 20.0, 60.0, 100.0]), np.array([0.0, 10.0, 35.0, 100.0])
    draws = np.stack([loam, loam, sandy_loam, np.full(4, np.nan)])
    report = texture.texture_report(d, sandy_loam, draws)
    written = report.save(tmp_path)
    assert [p.name for p in written] == ["texture.csv", "gradation.csv", "texture.png"]
    lines = (tmp_path / "texture.csv").read_text().splitlines()
    assert lines[0] == "system,fraction,percent,low,high"
    assert [tuple(line.split(",")[:2]) for line in lines[1:8]] == [
        ("USDA", "clay"), ("USDA", "silt"), ("USDA", "sand"),
        ("ISO 14688-1", "clay"), ("ISO 14688-1", "silt"), ("ISO 14688-1", "sand"), ("ISO 14688-1", "gravel")]
    assert lines[1].split(",")[2] == "10" and lines[8:] == [
        "USDA class (central),sandy loam,25,,", "USDA class,loam,50,,", "USDA class,unknown,25,,"]
    table = np.genfromtxt(tmp_path / "texture.csv", delimiter=",", names=True, dtype=None, encoding=None)
    assert table["percent"].dtype.kind == "f" and table["percent"].size == 10    # the percent column stays numeric
    gradation = (tmp_path / "gradation.csv").read_text().splitlines()
    assert gradation[0] == "quantity,value,low,high,unit,reached_percent"
    assert [line.split(",")[0] for line in gradation[1:7]] == ["D10", "D30", "D50", "D60", "Cu", "Cc"]
    assert [line.split(",")[4] for line in gradation[1:7]] == ["um"] * 4 + ["-"] * 2
    assert float(gradation[1].split(",")[1]) == pytest.approx(2.0)          # the sandy loam is at 10 % at 2 um
    assert float(gradation[1].split(",")[5]) == pytest.approx(75.0)          # the NaN draw reaches nothing
    assert len(gradation) == 7 + sum(line.startswith("# ") for line in gradation)


def test_quantities_the_curve_does_not_reach_are_empty_with_the_reason(tmp_path):
    d = np.array([1e-6, 100e-6])
    report = texture.texture_report(d, np.array([15.0, 55.0]), np.array([[15.0, 55.0], [16.0, 56.0]]))
    report.save(tmp_path)
    lines = (tmp_path / "gradation.csv").read_text().splitlines()
    rows = {line.split(",")[0]: line.split(",") for line in lines[1:] if not line.startswith("#")}
    assert rows["D10"] == ["D10", "", "", "", "um", "0"] and rows["D60"][1:4] == ["", "", ""]
    assert rows["Cu"][1:4] == ["", "", ""] and float(rows["D30"][1]) > 0
    notes = [line for line in lines if line.startswith("# ")]
    assert any(n.startswith("# D10 not reached") and "starts at 15 %" in n for n in notes)
    assert any(n.startswith("# D60 not reached") and "tops out at 55 %" in n for n in notes)
    assert any(n.startswith("# Cu not reached") and "D10, D60" in n for n in notes)
    assert report.summary()["gradation"]["D10"] == {"value": None, "band": [None, None]}


def test_a_report_without_draws_has_no_bands(tmp_path):
    report = texture.texture_report(D, P)
    rows = report.texture_table().rows
    assert rows[0][:2] == ["USDA", "clay"] and rows[0][3:] == ["", ""]
    assert rows[-1] == ["USDA class (central)", "loam", "", "", ""]
    assert "no draws" in report.usda_class_line()
    assert "no draws of the curve: no bands" in report.gradation_table().notes
    assert "USDA texture class" in report.table().text()
    assert all(path.stat().st_size > 0 for path in report.save(tmp_path))


def test_both_figures_render(tmp_path, monkeypatch):
    drawn = []
    save = texture.figures.save

    def keep(fig, path, **kwargs):
        drawn.append((fig.axes[0].get_xlim(), len(fig.axes[0].patches), [t.get_text() for t in fig.axes[0].texts]))
        return save(fig, path, **kwargs)

    monkeypatch.setattr(texture.figures, "save", keep)
    central, draws = _shifted(5.0, 90.0)
    triangle = texture.texture_report(D, central, draws[::20]).save(tmp_path)[2]
    _, polygons, labels = drawn[-1]
    assert polygons == len(texture.USDA_CLASSES)
    assert {label.replace("\n", " ") for label in labels} >= set(texture.USDA_CLASSES)
    chart = texture.gradation_figure(tmp_path / "gradation.png", D, central, central - 2, central + 2,
                                     (np.array([75e-6, 2e-3, 4.75e-3]), np.array([70.0, 95.0, 100.0])),
                                     [("standard reduction (152H)", np.array([5e-6, 20e-6]), np.array([30.0, 45.0]))])
    (left, right), _, labels = drawn[-1]
    assert left <= 0.5 and right >= 4750
    assert any(label.startswith("D10 = ") for label in labels) and any("ISO silt | sand" in t for t in labels)
    bare = texture.gradation_figure(tmp_path / "bare.png", D[:30], P[:30])    # no band, no points; D60 not reached
    assert not any(label.startswith("D60") for label in drawn[-1][2])
    for path in (triangle, chart, bare):
        assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
