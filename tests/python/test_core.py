# SPDX-License-Identifier: GPL-2.0-or-later
"""The physics core as Python sees it (the same code the LAMMPS styles run)."""
import math

import pytest

import sediment
from sediment import _core


def test_case_a_terminal_velocity_and_tau():
    speed, regime = sediment.terminal_velocity("stokes", 1000.0, 1e-3, 0.0, 1e-4, 2700.0, 9.81)
    assert regime == "moving"
    assert speed == pytest.approx(1700 * 9.81 * 1e-8 / 18e-3, rel=1e-13)
    assert sediment.relaxation_time("stokes", 1000.0, 1e-3, 1e-4, 2700.0) == pytest.approx(1.5e-3, rel=1e-13)
    t99 = sediment.time_to_fraction("stokes", 1000.0, 1e-3, 0.0, 1e-4, 2700.0, 9.81, 0.99)
    assert t99 == pytest.approx(1.5e-3 * math.log(100), rel=1e-10)


def test_law_names_and_coefficients():
    assert sediment.drag_law_names() == ["stokes", "schiller-naumann", "dallavalle", "zhang-li", "zhang-li/smooth",
                                         "difelice", "standard", "bingham"]
    assert sediment.drag_coefficient("schiller-naumann", 10.0) == pytest.approx(2.4 * (1 + 0.15 * 10**0.687))
    assert sediment.drag_coefficient("dallavalle", 4.0) == pytest.approx((0.63 + 2.4) ** 2)
    assert sediment.drag_coefficient("zhang-li", 10.0) == pytest.approx(2.912 + 0.195)


def test_bingham_rest_criterion_and_jumps():
    assert sediment.critical_yield_number("zhang-li") == pytest.approx(0.0440, abs=5e-5)
    model = sediment.DragModel("zhang-li", 1280.0, 0.0131, 30.5)
    jumps = model.jumps(0.0254)
    assert [round(model.reynolds(0.0254, v), 9) for v, _, _ in jumps] == [1.0, 150.0]
    assert all(above > below for _, below, above in jumps)
    assert model.static_force(0.02) == pytest.approx((math.pi**2 / 4 + 3 * math.pi) * 0.02**2 * 30.5)
    # law bingham: Beris et al.'s critical yield number, no jump, the standard curve in water
    assert sediment.critical_yield_number("bingham") == pytest.approx(0.048, rel=1e-12)
    bingham = sediment.DragModel("bingham", 1280.0, 0.0131, 30.5)
    assert bingham.jumps(0.0254) == []
    assert bingham.static_force(0.02) == pytest.approx(math.pi / 6 / 0.048 * 0.02**2 * 30.5, rel=1e-12)
    water = sediment.DragModel("bingham", 998.2, 1.002e-3), sediment.DragModel("standard", 998.2, 1.002e-3)
    assert water[0].force(1e-3, 0.05) == pytest.approx(water[1].force(1e-3, 0.05), rel=1e-14)
    with pytest.raises(ValueError, match="yield_weight must be > 0"):
        sediment.DragModel("bingham", 1280.0, 0.0131, 30.5, yield_weight=0.0)


def test_submergence_half():
    sub = sediment.submergence(1.0, 0.0)
    assert sub == pytest.approx({"volume": 0.5, "area": 1.0, "wetted": 0.5})


def test_rayleigh_time_example():
    assert sediment.rayleigh_time(0.05e-3, 2700, 30e9, 0.25) == pytest.approx(8.12e-8, rel=1e-3)


@pytest.mark.parametrize("call, message", [
    (lambda: sediment.DragModel("stoke", 1000, 1e-3), "unknown drag law 'stoke'"),
    (lambda: sediment.DragModel("stokes", -1, 1e-3), "density must be > 0"),
    (lambda: sediment.DragModel("stokes", 1000, 0), "viscosity must be > 0"),
    (lambda: sediment.terminal_velocity("stokes", 1000, 1e-3, 0, -1e-4, 2700), "diameter must be > 0"),
    (lambda: sediment.time_to_fraction("stokes", 1000, 1e-3, 0, 1e-4, 2700, 9.81, 1.5), "fraction must be in"),
    (lambda: _core.spring_step_limit(-1.0, 0.0), "omega and rate must be finite and >= 0"),
    (lambda: _core.spring_step_limit(1e4, float("nan")), "omega and rate must be finite and >= 0"),
    (lambda: _core.hertz_contact_frequency("floor", 1e-4, 2650, 1e6, 0.3, 0.01), "impact must be 'wall' or 'pair'"),
])
def test_bad_input_raises_clear_errors(call, message):
    with pytest.raises(ValueError, match=message):
        call()


@pytest.mark.parametrize("phi, richardson_zaki", [(0.1, 0.613), (0.2, 0.354), (0.3, 0.190), (0.4, 0.093)])
def test_difelice_hindered_settling_near_richardson_zaki(phi, richardson_zaki):
    model = sediment.DragModel("difelice", 1000.0, 1e-3)
    weight = 1650 * 9.81 * math.pi / 6 * (5e-6) ** 3
    single, _ = model.steady_speed(5e-6, weight)
    hindered, _ = model.steady_speed(5e-6, weight, voidage=1 - phi)
    assert hindered / single == pytest.approx(richardson_zaki, rel=0.03)


def test_voidage_and_buoyancy_are_validated():
    with pytest.raises(ValueError, match="voidage must be in"):
        sediment.DragModel("difelice", 1000, 1e-3).force(1e-4, 1e-3, voidage=0.0)
    with pytest.raises(ValueError, match="buoyancy must be 'plain' or 'mixture'"):
        sediment.DragModel("difelice", 1000, 1e-3, buoyancy="heavy")
