# SPDX-License-Identifier: GPL-2.0-or-later
"""Deck tests of the SEDIMENT styles: `python3 checks.py NAME [--np N]` (run by ctest).

Each check runs decks through lmp_sediment (serial or mpirun) and compares what they print with
analytic references from the physics core. The numbers they print are the measured results.
"""
from __future__ import annotations

import argparse
import csv
import math
import os
import tempfile
from pathlib import Path

import numpy as np

import styles
import field_checks  # noqa: F401  (its checks register themselves, as those of the next two)
import flow_checks  # noqa: F401
import refusals  # noqa: F401
from harness import CHECKS, HERE, G, check, report, run_deck
from style_table import declared_styles

try:    # (the harness puts python/ on the path)
    from sediment import _core
except ImportError as not_built:    # listing the checks, at configure time before the build, needs none
    _core, _core_missing = None, not_built

DATA = HERE.parent / "data"    # the validation data the checks compare with (tests/data)


def stokes_reference(d: float, rho_p: float, rho_f: float = 1000.0, mu: float = 1e-3):
    vt = (rho_p - rho_f) * G * d * d / (18 * mu)
    tau = rho_p * d * d / (18 * mu)
    return vt, tau


# ---- case A: single sphere in water (Zhang & Li 2024) ---------------------------------------
def case_a_errors(dt: float, t_end: float, integrator: str, np_ranks: int):
    steps = max(1, round(t_end / dt))
    out = run_deck("single_sphere.lmp", {"dt": dt, "steps": steps, "integrator": integrator,
                                         "every": max(1, steps // 200)}, np_ranks)
    vt, tau = stokes_reference(1e-4, 2700.0)
    t, z, vz = out.samples[:, 0], out.samples[:, 1], out.samples[:, 2]
    v_exact = -vt * (1 - np.exp(-t / tau))
    z_exact = -vt * (t - tau * (1 - np.exp(-t / tau)))
    v_err = float(np.max(np.abs(vz - v_exact)) / vt)
    z_err = float(np.max(np.abs(z - z_exact)) / (vt * t_end))
    return v_err, z_err, out


@check
def case_a_implicit(np_ranks: int):
    vt, tau = stokes_reference(1e-4, 2700.0)
    for dt in (1e-3, 1e-1, 100 * tau):
        v_err, z_err, _ = case_a_errors(dt, max(0.03, 10 * dt), "nve/sphere/fluid", np_ranks)
        report(f"case A implicit dt={dt:.3g} s (dt/tau={dt / tau:.3g}): "
               f"max|v-v_exact|/v_t={v_err:.2e}  max|z-z_exact|/(v_t T)={z_err:.2e}")
        assert v_err < 1e-6 and z_err < 1e-6


@check
def case_a_explicit(np_ranks: int):
    vt, tau = stokes_reference(1e-4, 2700.0)
    for dt in (1e-5, 1e-4, 2.5e-3):
        v_err, z_err, out = case_a_errors(dt, 0.03, "nve/sphere", np_ranks)
        report(f"case A explicit dt={dt:.3g} s (dt/tau={dt / tau:.3g}): max|v-v_exact|/v_t={v_err:.2e}")
        assert "dt > 2 tau" not in out.text
        if dt <= 1e-4:
            assert 0.05 * dt / tau < v_err < 0.5 * dt / tau    # first order in dt / tau
        else:
            assert 1e-2 < v_err < 1.0        # stable but oscillating below 2 tau
    v_err, _, out = case_a_errors(3.5e-3, 0.1, "nve/sphere", np_ranks)
    report(f"case A explicit dt=3.5e-3 s (dt/tau={3.5e-3 / tau:.3g}): max|v-v_exact|/v_t={v_err:.2e} (diverges)")
    assert v_err > 10.0
    assert "1 sphere(s) have dt > 2 tau under explicit drag" in out.text


# ---- case B: terminal velocities of fine grains (Bravo et al. 2015) -------------------------
@check
def case_b(np_ranks: int):
    # d [um], table time [1e-5 s], v_t [1e-5 m/s], fraction of v_t the table's time refers to
    # (tau ln 100 for 70 um, tau ln 20 for the finer rows: see tests/core/test_terminal.cpp).
    rows = [(70, 313.4, 400.5, 0.99), (50, 104.0, 204.3, 0.95), (25, 26.0, 51.09, 0.95),
            (10, 4.16, 8.17, 0.95), (5, 1.04, 2.04, 0.95), (2.5, 0.26, 0.51, 0.95)]
    for d_um, t_tab, vt_tab, fraction in rows:
        t_table = t_tab * 1e-5
        out = run_deck("single_sphere.lmp", {"d": d_um * 1e-6, "rho_p": 2500, "dt": t_table / 20,
                                             "steps": 20 * 40, "every": 20}, np_ranks)
        v_at_table_time = -out.samples[1, 2]
        vt_sim = -out.samples[-1, 2]
        reached = v_at_table_time / vt_sim
        report(f"case B d={d_um} um: v_t={vt_sim / 1e-5:.4f}e-5 m/s (table {vt_tab}), "
               f"v(t_table)/v_t={reached:.5f} (expected {fraction})")
        assert abs(vt_sim / 1e-5 - vt_tab) <= 1e-3 * vt_tab + 0.005
        assert abs(reached - fraction) <= 1e-3 * fraction


# ---- case C: spheres in clay suspensions (Valentik & Whitmore 1965) -------------------------
def case_c_deck(rows: list[dict], path: Path, law: str) -> None:
    lines = ["units si", "atom_style sphere", "atom_modify map array", "boundary p p m",
             f"region box block -1 {len(rows)} -1 1 -1 1", f"create_box {len(rows)} box",
             "comm_modify cutoff 1.0", "fix grav all gravity 9.81 vector 0 0 -1"]
    for i, row in enumerate(rows, start=1):
        lines += [f"create_atoms {i} single {i - 0.5} 0 0",
                  f"set atom {i} diameter {row['d']} density {row['rho_p']}",
                  f"group s{i} type {i}",
                  f"fix fluid{i} s{i} fluid density {row['rho_f']} bingham {row['tau_y']} {row['eta_B']}",
                  f"fix buoy{i} s{i} fluid/buoyancy fluid{i}",
                  f"fix drag{i} s{i} fluid/drag fluid{i} law {law}"]
    lines += ["fix step all nve/sphere/fluid", "timestep 0.01", "thermo 0", "run 20000"]
    lines += [f'print "RESULT v{i} $(vz[{i}]:%.17g)"' for i in range(1, len(rows) + 1)]
    path.write_text("\n".join(lines) + "\n")


@check
def case_c(np_ranks: int):
    data = DATA / "vw1965_dev.csv"
    with open(data) as f:
        rows = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(f)]
    for law in ("zhang-li", "zhang-li/smooth", "bingham"):
        with tempfile.TemporaryDirectory() as tmp:
            deck = Path(tmp) / "case_c.lmp"
            case_c_deck(rows, deck, law)
            out = run_deck(deck, {}, np_ranks, cwd=Path(tmp))
        worst = 0.0
        for i, row in enumerate(rows, start=1):
            speed, regime = _core.terminal_velocity(law, row["rho_f"], row["eta_B"], row["tau_y"],
                                                    row["d"], row["rho_p"], G)
            sim = -out.results[f"v{i}"]
            dev = (sim - speed) / speed
            worst = max(worst, abs(dev))
            report(f"case C {law:16s} susp {int(row['suspension'])} d={row['d'] * 1e3:5.1f} mm "
                   f"rho_p={row['rho_p']:.0f}: sim {sim:.5f} m/s, law {speed:.5f} ({regime}), "
                   f"sim-law {dev:+.1e}, measured {row['v_ter_measured']:.3f} "
                   f"(law vs measured {(speed - row['v_ter_measured']) / row['v_ter_measured']:+.1%})")
            assert abs(dev) < 0.005
        report(f"case C {law}: worst |sim - law| / law = {worst:.1e}")


# ---- cases D and F: steel ball into paste, drop test (examples/paste) -------------------------
PASTE_DECKS = HERE.parents[1] / "examples" / "paste"


@check
def paste(np_ranks: int):
    out = run_deck(PASTE_DECKS / "in.drop_test", {"fall": 0.252}, np_ranks, cwd=PASTE_DECKS)
    e = math.sqrt(out.results["rebound"] / 0.252)
    report(f"drop test from 252 mm: rebound {out.results['rebound'] * 1e3:.2f} mm, e = {e:.4f}")
    assert abs(e - 0.612) < 1e-3
    out = run_deck(PASTE_DECKS / "in.collision", {"speed": 1.7}, np_ranks, cwd=PASTE_DECKS)
    report(f"two 12.6 mm balls head-on at 1.7 m/s with the wall's damping input: e = {out.results['restitution']:.4f}")
    assert abs(out.results["restitution"] - 0.612) < 1e-3
    out = run_deck(PASTE_DECKS / "in.ball_in_paste", {"d": 0.0126, "fall": 0.255}, np_ranks, cwd=PASTE_DECKS)
    r = out.results
    report(f"12.6 mm ball from 255 mm: at rest {r['depth'] * 1e3:.3f} mm below the surface after {r['t_rest']} s, "
           f"creep over the hold {r['creep']}, speed {r['vz']}")
    assert r["stuck"] == 1 and r["creep"] == 0 and r["vz"] == 0 and 0 < r["depth"] < 0.150 - 0.0126


@check
def struck_ball(np_ranks: int):
    # A ball held by the paste's yield stress takes a blow from above as a free ball would: the blow's
    # impulse (about 1e-2 N s in 50 us) dwarfs the yield's (0.26 N over the same 50 us, 1.3e-5 N s).
    v0, e = 1.0, 0.612
    after = {}
    for rheology in ("bingham 136 0.7", "viscosity 0.7"):
        out = run_deck("struck_ball.lmp", {"mode": "impact", "v0": v0, "rheology": rheology, "dt": 1e-7,
                                           "steps": 1000, "every": 1000}, np_ranks)
        after[rheology.split()[0]] = out.samples[-1, [2, 4]]    # vz of A and B 100 us after the blow
    free = np.array([-(1 - e) / 2 * v0, -(1 + e) / 2 * v0])
    report(f"held ball struck at {v0} m/s: vz (A, B) after the blow {after['bingham']} in paste, "
           f"{after['viscosity']} without yield stress, free-ball collision {free}")
    assert np.all(np.abs(after["bingham"] - free) < 0.01 * v0)
    assert np.all(np.abs(after["bingham"] - after["viscosity"]) < 0.005 * v0)
    # Loaded through a contact, it stays exactly still up to its yield resistance and sinks beyond.
    d, rho, rho_paste, tau_y = 0.0126, 8135.0, 1843.0, 136.0
    volume = math.pi * d ** 3 / 6
    resistance = (math.pi ** 2 / 4 + 3 * math.pi) * d * d * tau_y    # spec/physics.md section 4
    for ratio in (0.98, 1.02):
        weight_a = ratio * resistance - (rho - rho_paste) * G * volume
        out = run_deck("struck_ball.lmp", {"mode": "load", "rho_A": weight_a / (G * volume), "dt": 1e-6,
                                           "steps": 50000, "every": 500}, np_ranks)
        z_b, vz_b = out.samples[:, 3], out.samples[:, 4]
        report(f"held ball loaded to {ratio} of its yield resistance through a contact: B moved "
               f"{abs(z_b[-1] - z_b[0]):.3g} m in 0.05 s, vz {vz_b[-1]:.3g} m/s, held {out.results['stuck_B']:.0f}")
        if ratio < 1:
            assert np.all(z_b == z_b[0]) and np.all(vz_b == 0) and out.results["stuck_B"] == 1
        else:
            assert vz_b[-1] < -1e-3 and out.results["stuck_B"] == 0


@check
def contact_overlap(np_ranks: int):
    # A: 10 um between two 1 mm spheres, relative 10 um / 1 mm; B: 2 um between 2 mm and 0.5 mm spheres,
    # relative 2 um / (4 a) with a = 0.2 mm; C apart. Newton on and off (a pair across ranks seen twice).
    for newton in ("on", "off"):
        r = run_deck("contact_overlap.lmp", {"newton": newton}, np_ranks).results
        report(f"contact/overlap (newton {newton}): relative {r['relative']:.15g}, largest {r['largest']:.6g} m, "
               f"contacts {r['contacts']:.0f}")
        assert abs(r["relative"] - 0.01) < 1e-9 and abs(r["largest"] - 1e-5) < 1e-15 and r["contacts"] == 2


@check
def hertz_impact(np_ranks: int):
    # The soft-contact rule: two 75 um grains of 2650 kg/m3 meeting at 4 mm/s with the modulus the
    # rule gives for a 1 % overlap reach 1 % (undamped Hertz), whatever the step that resolves the contact.
    d, rho, v, tolerance = 75e-6, 2650.0, 4e-3, 0.01
    youngs = _core.hertz_modulus_for_overlap("pair", rho, v, tolerance, 0.3)
    rayleigh = _core.rayleigh_time(d / 2, rho, youngs, 0.3)
    dt = rayleigh / 50
    # The initial gap (0.2 um) and the contact (Hertz: 2.94 delta_max / v) with room to spare.
    contact = (2e-7 + 4 * d * tolerance) / v
    out = run_deck("hertz_impact.lmp", {"d": d, "rho": rho, "v": v, "E": youngs, "dt": dt,
                                        "steps": round(contact / dt)}, np_ranks)
    largest = float(out.samples[:, 1].max())
    report(f"Hertz impact at {v} m/s with E = {youngs:.4g} Pa (rule for {tolerance:.0%}): largest overlap "
           f"{largest:.5%} of d, dt = Rayleigh time / 50 = {dt:.3g} s")
    assert abs(largest - tolerance) < 2e-3 * tolerance and out.samples[-1, 1] == 0.0


@check(ranks=(1,))
def soft_bed(np_ranks: int):
    # 320 quartz grains of 60-100 um settle onto a floor in water with the soft-contact rule's modulus (1 %
    # overlap for the fastest grain's impact at its Dallavalle terminal speed) and with 16 times that
    # (a quarter of the step). The soft bed keeps its overlaps within the 1 %, and its height and packing
    # fraction match the stiff bed's. (Serial: the compute's ranks are checked by contact_overlap.)
    rho, v_max = 2650.0, float(_core.terminal_velocity("dallavalle", 1000.0, 1e-3, 0.0, 1e-4, 2650.0, G)[0])
    soft = _core.hertz_modulus_for_overlap("wall", rho, v_max, 0.01, 0.3)
    beds = {}
    with tempfile.TemporaryDirectory() as tmp:
        for name, youngs in (("soft", soft), ("stiff", 16 * soft)):
            dt = 0.2 * _core.rayleigh_time(30e-6, rho, youngs, 0.3)
            final = Path(tmp) / f"{name}.txt"
            out = run_deck("soft_bed.lmp", {"E": youngs, "dt": dt, "t_end": 0.5, "every": 100, "final": final},
                           np_ranks)
            grains = np.loadtxt(final, skiprows=9)
            volume = np.pi / 6 * grains[:, 4] ** 3
            mean_height = float(np.sum(volume * grains[:, 3]) / volume.sum())    # half the bed's height
            beds[name] = (out.samples[:, 1].max(), mean_height, volume.sum() / (1e-6 * 2 * mean_height), grains)
    (o_soft, h_soft, phi_soft, g_soft), (o_stiff, h_stiff, phi_stiff, _) = beds["soft"], beds["stiff"]
    report(f"soft bed: E = {soft:.3g} Pa (rule for 1 % at {v_max:.3g} m/s): largest overlap {o_soft:.3%}, "
           f"mean height {h_soft * 1e3:.4f} mm, packing fraction {phi_soft:.4f}; 16 x stiffer: largest overlap "
           f"{o_stiff:.3%}, mean height {h_stiff * 1e3:.4f} mm, packing fraction {phi_stiff:.4f}")
    assert o_soft < 0.01 and o_stiff < o_soft
    assert abs(h_soft / h_stiff - 1) < 0.02 and abs(phi_soft / phi_stiff - 1) < 0.02
    assert g_soft[:, 3].max() < 0.00025    # every grain came down into the bed (it started 0.3 mm up or higher)


# ---- Bingham hard cases -----------------------------------------------------------------------
CLAY = dict(rho_f=1280.0, eta=0.0131, tau_y=30.5)
D_BALL = 0.02


def bingham_vars(law: str, y_ratio: float, **extra) -> dict:
    yc = _core.critical_yield_number(law)
    rho_p = CLAY["rho_f"] + CLAY["tau_y"] / (yc * y_ratio * G * D_BALL)
    return {"d": D_BALL, "rho_p": rho_p, "rho_f": CLAY["rho_f"], "law": law,
            "rheology": f"bingham {CLAY['tau_y']} {CLAY['eta']}", **extra}


@check
def bingham_rest(np_ranks: int):
    for law in ("zhang-li", "bingham"):
        out = run_deck("single_sphere.lmp", bingham_vars(law, 1.0001, dt=1e-3, steps=100000, every=1000),
                       np_ranks)
        report(f"Bingham {law} Y = 1.0001 Y_c: max |vz| over 1e5 steps = {np.max(np.abs(out.samples[:, 2])):.1e}, "
               f"max |z| = {np.max(np.abs(out.samples[:, 1])):.1e}, stuck spheres = {out.results['stuck']:.0f}")
        assert np.all(out.samples[:, 1:] == 0.0)
        assert out.results["stuck"] == 1


@check
def bingham_settles(np_ranks: int):
    for law in ("zhang-li", "zhang-li/smooth", "bingham"):
        for dt in (1e-3, 0.1):
            out = run_deck("single_sphere.lmp", bingham_vars(law, 0.99, dt=dt, steps=round(300 / dt),
                                                                 every=round(300 / dt)), np_ranks)
            v = bingham_vars(law, 0.99)
            speed, regime = _core.terminal_velocity(law, CLAY["rho_f"], CLAY["eta"], CLAY["tau_y"], D_BALL,
                                                    v["rho_p"], G)
            sim = -out.samples[-1, 2]
            report(f"Bingham Y = 0.99 Y_c {law} dt={dt}: v={sim:.9f} m/s, law {speed:.9f} ({regime})")
            assert abs(sim - speed) < 1e-8 * speed


@check
def bingham_jump(np_ranks: int):
    model = _core.DragModel("zhang-li", CLAY["rho_f"], CLAY["eta"], CLAY["tau_y"])
    volume = math.pi * D_BALL ** 3 / 6
    for j, (speed, below, above) in enumerate(model.jumps(D_BALL)):
        rho_p = CLAY["rho_f"] + 0.5 * (below + above) / (G * volume)
        for dt in (1e-4, 1e-2, 1.0):
            settle = max(200, round(5.0 / dt))
            out = run_deck("single_sphere.lmp", {"d": D_BALL, "rho_p": rho_p, "rho_f": CLAY["rho_f"],
                                                 "law": "zhang-li",
                                                 "rheology": f"bingham {CLAY['tau_y']} {CLAY['eta']}",
                                                 "dt": dt, "steps": settle + 100, "every": 1}, np_ranks)
            tail = -out.samples[-100:, 2]
            spread = float(np.max(np.abs(tail - speed)) / speed)
            report(f"Cd jump {j} (v={speed:.5f} m/s) dt={dt}: max |v - v_jump|/v_jump over the last 100 "
                   f"steps = {spread:.1e}, held = {out.results['at_jump']:.0f}")
            assert spread < 1e-9 and out.results["at_jump"] == 1


# ---- free surface -------------------------------------------------------------------------------
@check
def surface_crossing(np_ranks: int):
    r = 0.5e-3
    volume = 4 / 3 * math.pi * r ** 3
    full = 1000 * G * volume
    # A fixed surface, one that rises at 0.5 mm/s (a variable), and the paper's switch at the centre.
    for crossing, rise in (("cap", 0.0), ("cap", 5e-4), ("centre", 0.0)):
        out = run_deck("surface_crossing.lmp", {"crossing": crossing, "rise": rise}, np_ranks)
        t, z, force = out.samples[:, 0], out.samples[:, 1], out.samples[:, 2]
        height = z - rise * t
        if crossing == "cap":
            expected = np.array([full * _core.submergence(r, h)["volume"] for h in height])
        else:
            expected = np.where(height <= 0, full, 0.0)
        err = float(np.max(np.abs(force - expected)) / full)
        steps = np.abs(np.diff(force)) / full
        report(f"surface crossing ({crossing}, surface rising at {rise} m/s): max |F_b - expected| / (rho g V) = "
               f"{err:.1e}; largest change between samples {steps.max():.3e} of the full buoyancy (sample spacing "
               f"{abs(height[1] - height[0]) / (2 * r):.3f} d)")
        assert err < 1e-12
        if crossing == "cap":    # continuous: the slope of V_cap is at most 1.5 V / d
            assert steps.max() < 3 * abs(height[1] - height[0]) / (2 * r)
        else:
            assert np.sum(steps > 0.5) == 1


@check
def floating(np_ranks: int):
    d, rho_p = 1e-3, 700.0
    out = run_deck("single_sphere.lmp", {"d": d, "rho_p": rho_p, "extra": "surface z 0", "z0": -d,
                                         "dt": 1e-3, "steps": 4000, "every": 4000}, np_ranks)
    lo, hi = -d / 2, d / 2    # centre height where the submerged fraction equals rho_p / rho_f
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if _core.submergence(d / 2, mid)["volume"] < rho_p / 1000 else (mid, hi)
    z_eq = 0.5 * (lo + hi)
    z = out.samples[-1, 1]
    report(f"floating sphere rho_p/rho_f=0.7: rest height {z / d:+.9f} d, Archimedes {z_eq / d:+.9f} d")
    assert abs(z - z_eq) < 1e-6 * d and abs(out.samples[-1, 2]) < 1e-9


@check
def neutral_buoyancy(np_ranks: int):
    # A sphere as dense as the fluid displaces exactly the mass LAMMPS gave it (set density), so
    # gravity and buoyancy cancel to the bit and it stays where it was released, under either
    # integrator and a linear or a nonlinear law (no slip: no drag).
    cases = [(3e-5, 998.2, "stokes", "nve/sphere/fluid"), (1e-4, 998.2, "dallavalle", "nve/sphere/fluid"),
             (7.3e-4, 1234.5, "schiller-naumann", "nve/sphere"), (2.1e-3, 1000.0, "stokes", "nve/sphere")]
    for d, rho, law, integrator in cases:
        out = run_deck("single_sphere.lmp", {"d": d, "rho_p": rho, "rho_f": rho, "law": law,
                                             "integrator": integrator, "dt": 1e-3, "steps": 200, "every": 200},
                       np_ranks)
        z, vz = out.samples[-1, 1], out.samples[-1, 2]
        report(f"neutrally buoyant d={d:g} rho={rho:g} {law} {integrator}: z {z:g}, vz {vz:g} after 200 steps")
        assert z == 0.0 and vz == 0.0


# ---- integrator -----------------------------------------------------------------------------------
@check
def integrator_order(np_ranks: int):
    base = {"d": 2e-3, "rho_p": 2500, "rheology": "viscosity 0.05", "law": "schiller-naumann",
            "tether": 2.0, "vx0": 0.05}
    t_end = 0.4

    def trajectory(dt):    # z, vz, vx at 10 common times
        steps = round(t_end / dt)
        out = run_deck("single_sphere.lmp", {**base, "dt": dt, "steps": steps, "every": steps // 10}, np_ranks)
        return out.samples[1:, 1:]

    ref = trajectory(1e-3 / 64)
    scale = np.max(np.abs(ref), axis=0)
    errors = [float(np.max(np.abs(trajectory(dt) - ref) / scale)) for dt in (1e-3, 5e-4, 2.5e-4)]
    orders = [math.log2(a / b) for a, b in zip(errors, errors[1:])]
    report(f"integrator order (spring + Schiller-Naumann drag): errors {['%.2e' % e for e in errors]}, "
           f"observed orders {['%.3f' % o for o in orders]}")
    assert all(1.8 < o < 2.2 for o in orders)


@check
def verlet_limit(np_ranks: int):
    with tempfile.TemporaryDirectory() as tmp:
        finals = []
        for integrator in ("nve/sphere", "nve/sphere/fluid"):
            dump = Path(tmp) / f"{integrator.replace('/', '_')}.txt"
            run_deck("granular_pile.lmp", {"integrator": integrator, "dump": dump}, np_ranks)
            finals.append(np.loadtxt(dump, skiprows=9))
    diff = float(np.max(np.abs(finals[0][:, 1:] - finals[1][:, 1:])))
    scale = float(np.max(np.abs(finals[0][:, 1:])))
    report(f"nve/sphere/fluid without a fluid vs nve/sphere, granular pile: max difference {diff:.1e} "
           f"(state scale {scale:.1e})")
    assert diff <= 1e-10 * scale


@check(ranks=())
def mpi_consistency(np_ranks: int):
    rng = np.random.default_rng(4321)
    n = 200
    atoms = np.column_stack([np.arange(1, n + 1), np.ones(n), rng.uniform(5e-5, 1.5e-4, n), np.full(n, 2600.0),
                             rng.uniform(0, 0.02, n), rng.uniform(0, 0.01, n), rng.uniform(0, 0.01, n)])
    with tempfile.TemporaryDirectory() as tmp:
        data = Path(tmp) / "settling.data"
        with open(data, "w") as f:
            f.write(f"settling spheres\n\n{n} atoms\n1 atom types\n\n0 0.02 xlo xhi\n0 0.01 ylo yhi\n"
                    "0 0.01 zlo zhi\n\nAtoms # sphere\n\n")
            np.savetxt(f, atoms, fmt=["%d", "%d", "%.17g", "%.17g", "%.17g", "%.17g", "%.17g"])
        finals = []
        for ranks in (1, 2):
            dump = Path(tmp) / f"np{ranks}.txt"
            run_deck("mpi_settling.lmp", {"data": data, "dump": dump}, ranks)
            finals.append(np.loadtxt(dump, skiprows=9))
    a, b = finals
    rel = float(np.max(np.abs(a - b) / np.maximum(np.abs(a), 1e-30)))
    report(f"1 vs 2 ranks, {len(a)} settling spheres crossing the rank boundary: max relative difference {rel:.1e}")
    assert len(a) == len(b) and rel < 1e-10


@check
def uniform_fast_path(np_ranks: int):
    """nve/sphere/fluid's uniform loop (a space-filling fluid: no region or surface look-up per atom)
    gives the same state, bit for bit, as the general per-atom path (taken when the fluid has a
    region, here covering everything), for the closed-form Stokes step, the smooth nonlinear step
    (Dallavalle) and hindered drag on the grid (Di Felice); the drag acts on a subgroup only, so
    the other spheres must move as under fix nve/sphere in both."""
    deck = """units si
atom_style sphere
atom_modify map array
boundary p p f
region box block 0 0.002 0 0.002 0 0.004
create_box 1 box
create_atoms 1 random 500 7 NULL
variable d atom 2e-5+4e-5*((floor(x/1e-5)+floor(y/1e-5)+floor(z/1e-5))%7)/6
set group all diameter v_d
set group all density 2650
velocity all set 1e-3 -2e-3 0 units box
comm_modify cutoff 1e-4
group dragged id <= 400
region everywhere block INF INF INF INF INF INF
compute conc all concentration/grid layers z 20
fix grav all gravity 9.81 vector 0 0 -1
fix water all fluid density 998.2 viscosity 1.002e-3 velocity 1e-4 0 0 ${where}
fix buoy all fluid/buoyancy water
fix drag dragged fluid/drag water law ${law}
fix step all nve/sphere/fluid floor z 0
timestep 2e-3
run 300
write_dump all custom ${dump} id x y z vx vy vz omegax omegay omegaz modify sort id format float %.17g
"""
    with tempfile.TemporaryDirectory() as tmp:
        for law in ("stokes", "dallavalle", "difelice concentration c_conc"):
            states = []
            for where in ("", "region everywhere"):
                path, dump = Path(tmp) / f"fast{len(states)}.lmp", Path(tmp) / f"state{len(states)}.txt"
                path.write_text(deck.replace("${where}", where).replace("${law}", law))
                run_deck(path, {"dump": dump}, np_ranks, cwd=Path(tmp))
                states.append(np.loadtxt(dump, skiprows=9))
            fast, general = states
            moving = int(np.sum(np.abs(general[:, 6]) > 0))
            # the undragged spheres (ids above 400) fall freely: faster than any dragged one
            free = general[general[:, 0] > 400]
            dragged = general[general[:, 0] <= 400]
            suspended = int(np.sum(dragged[:, 3] > 1e-4))
            report(f"{law.split()[0]}: uniform vs general path: {len(fast)} spheres ({moving} still settling, "
                   f"{suspended} dragged ones above the floor), max difference {np.max(np.abs(fast - general)):.1e}; "
                   f"undragged: highest centre {free[:, 3].max():.2g} m")
            assert fast.shape == general.shape and moving > 0 and np.array_equal(fast, general)
            # Without drag the other spheres fall the 4 mm in about 40 ms: all rest on the floor.
            assert suspended > 100 and free[:, 3].max() <= 3e-5 * (1 + 1e-9) and not np.any(free[:, 4:7])


# ---- deposit on a floor, weighted layers -----------------------------------------------------
def deposit_run(np_ranks: int, law: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The deposit deck under `law`: the states at 5 s and 50 s, the first layer profile, and the
    state after ten spheres were pushed along the floor and ten lifted off it for 5 s."""
    with tempfile.TemporaryDirectory() as tmp:
        files = {name: Path(tmp) / f"{name}.txt" for name in ("mid", "final", "profile", "pushed")}
        run_deck("deposit.lmp", {"law": law, **files}, np_ranks)
        at5, at50 = np.loadtxt(files["mid"], skiprows=9), np.loadtxt(files["final"], skiprows=9)
        first = np.loadtxt(files["profile"], comments="#", skiprows=4, max_rows=101)[:, 2]
        pushed = np.loadtxt(files["pushed"], skiprows=9)
    return at5, at50, first, pushed


def check_moved_off_rest(law: str, at50: np.ndarray, pushed: np.ndarray) -> None:
    """Settled spheres stay exactly at rest, unless pushed along the floor (they slide and stay on
    it) or lifted off it (under a smooth law the step of a resting sphere is skipped: only while
    nothing moves it)."""
    x0, (x, z, vz, r) = at50[:, 7], pushed[:, 1:5].T    # at50: id z vz radius weight vx vy x
    ids = pushed[:, 0]
    push, lift, rest = ids <= 10, (ids > 10) & (ids <= 20), ids > 20
    report(f"deposit under {law}: settled spheres still at rest {bool(np.all(z[rest] == r[rest]))}; "
           f"pushed ones slid {np.min(np.abs(x[push] - x0[push])):.2e} m at least and stay on the floor "
           f"{bool(np.all(z[push] == r[push]))}; lifted ones rose {np.min(z[lift] - r[lift]):.2e} m at least")
    assert np.all(z[rest] == r[rest]) and np.all(vz[rest] == 0)
    assert np.all(z[push] == r[push]) and np.all(x[push] != x0[push])
    assert np.all(z[lift] > r[lift])


@check
def deposit(np_ranks: int):
    at5, at50, first, pushed = deposit_run(np_ranks, "stokes")
    z, vz, r, weight = at5[:, 1], at5[:, 2], at5[:, 3], at5[:, 4]
    vt, tau = stokes_reference(2 * r, 2650.0)
    t = 5.0
    free = 0.005 - vt * (t - tau * (1 - np.exp(-t / tau)))    # exact for Stokes drag at any dt
    down = free <= r
    moving_err = float(np.max(np.abs(z[~down] - free[~down]) / (vt[~down] * t)))
    report(f"deposit at t = 5 s: {down.sum()} of {len(z)} spheres on the floor (z = r, v = 0 exactly: "
           f"{bool(np.all(z[down] == r[down]) and np.all(vz[down] == 0))}); the others within {moving_err:.1e} "
           f"of the exact Stokes fall")
    assert 0 < down.sum() < len(z) and np.all(z[down] == r[down]) and np.all(vz[down] == 0)
    assert moving_err < 1e-10
    assert np.all(at50[:, 1] == at50[:, 3]) and np.all(at50[:, [2, 5, 6]] == 0)
    solid = float(np.sum(weight * 4 / 3 * np.pi * r ** 3))
    weighted = first.sum() * 0.002 * 0.002 * 0.0102 / 101
    report(f"weighted layers: sum of fraction x layer volume = {weighted:.6e} m3, sum of weight x sphere volume "
           f"= {solid:.6e} m3 (relative {abs(weighted - solid) / solid:.1e}); all {len(at50)} on the floor at 50 s")
    assert abs(weighted - solid) < 1e-12 * solid
    check_moved_off_rest("stokes", at50, pushed)
    _, at50, _, pushed = deposit_run(np_ranks, "dallavalle")
    assert np.all(at50[:, 1] == at50[:, 3]) and np.all(at50[:, [2, 5, 6]] == 0)
    check_moved_off_rest("dallavalle", at50, pushed)


# ---- lubrication ------------------------------------------------------------------------------
def lubrication_run(np_ranks: int, **variables) -> np.ndarray:
    return run_deck("lubrication.lmp", variables, np_ranks).samples    # time, gap, approach speed


@check
def lubrication(np_ranks: int):
    mu, rho_f, d, rho_p = 1e-3, 1000.0, 1e-4, 2650.0
    a = d / 4    # effective radius of two equal spheres
    mass = rho_p * math.pi / 6 * d ** 3
    dt = _core.rayleigh_time(d / 2, rho_p, 3e10, 0.25) / 5    # the time step the Hertz contacts need

    # Coasting head-on: m_red dv/dt = -6 pi mu a^2 v / h with dh/dt = -v gives
    # v0 - v = K ln(h0 / h), K = 6 pi mu a^2 / m_red, down to the inner cutoff h_in = 0.01 a.
    k = 6 * math.pi * mu * a * a / (mass / 2)
    v0, h0 = 2.0 * k, 0.5 * a
    run = lubrication_run(np_ranks, speed=v0, gap0=h0, dt=dt, steps=int(0.6e-3 / dt), every=200)
    gap, speed = run[:, 1], run[:, 2]
    film = (gap > 0.01 * a) & (v0 - speed > 0.05 * v0)
    reynolds = k * np.log(h0 / gap[film])
    worst = float(np.max(np.abs((v0 - speed[film]) - reynolds) / reynolds))
    report(f"lubrication, head-on at v0 = {v0:.4g} m/s = 2 K, dt = {dt:.3g} s (T_R / 5): deceleration within "
           f"{100 * worst:.3f} % of K ln(h0/h) over {int(film.sum())} samples; at the end h = {gap[-1] / a:.4f} a, "
           f"v = {speed[-1] / v0:.1e} v0 (Reynolds: comes to rest at {math.exp(-2) * 0.5:.4f} a)")
    assert worst < 0.02 and gap.min() > 0.01 * a and speed.min() > -1e-9 * v0

    # The fastest grains of the sedimentation cases (70 um, v_t = 4.0e-3 m/s, case B) meeting head-on
    # at ten times that speed: the film stops them before the inner cutoff.
    d70 = 70e-6
    fast = lubrication_run(np_ranks, speed=0.04, gap0=0.5 * d70 / 4, d=d70, density=2500, dt=dt,
                           steps=int(1e-3 / dt), every=500)
    report(f"lubrication, 70 um grains head-on at 0.04 m/s: smallest gap {fast[:, 1].min() / (d70 / 4):.3f} a, "
           f"inner cutoff 0.01 a")
    assert fast[:, 1].min() > 0.01 * d70 / 4

    # Settling onto a held sphere with buoyancy, Stokes drag and the film, at the contact time step:
    # compare with the ODE m dv/dt = W - (3 pi mu d + c(h)) v, dh/dt = -v (RK4), above h_in.
    weight = (rho_p - rho_f) * G * math.pi / 6 * d ** 3
    v_start, h_start = weight / (3 * math.pi * mu * d), 0.6 * a
    t_end = 12e-3
    every = 2000
    settle = lubrication_run(np_ranks, settle=1, speed=v_start, gap0=h_start, dt=dt, steps=int(t_end / dt),
                             every=every)

    def rhs(state):
        h, v = state
        c = 6 * math.pi * mu * a * a / max(h, 0.01 * a) if h < 0.5 * a else 0.0
        return np.array([-v, (weight - (3 * math.pi * mu * d + c) * v) / mass])
    state, step, reference = np.array([h_start, v_start]), 1e-7, []
    for t in settle[:, 0]:
        while len(reference) == 0 or reference[-1][0] < t - 1e-12:
            if not reference:
                reference.append((0.0, *state))
                continue
            t0 = reference[-1][0]
            k1 = rhs(state); k2 = rhs(state + step / 2 * k1); k3 = rhs(state + step / 2 * k2); k4 = rhs(state + step * k3)
            state = state + step / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
            reference.append((t0 + step, *state))
    ref = np.array(reference)
    ref_gap = np.interp(settle[:, 0], ref[:, 0], ref[:, 1])
    above = ref_gap > 0.01 * a
    gap_err = float(np.max(np.abs(settle[above, 1] - ref_gap[above]) / ref_gap[above]))
    report(f"lubrication, settling onto a held sphere at dt = {dt:.3g} s: gap within {gap_err:.1e} (relative) of "
           f"the ODE over {int(above.sum())} samples down to h_in; final gap {settle[-1, 1]:.3g} m "
           f"(contact overlap), final speed {settle[-1, 2]:.3g} m/s")
    assert gap_err < 0.02
    assert abs(settle[-1, 2]) < 1e-3 * v_start and settle[-1, 1] > -1e-3 * d    # resting on the contact

    # Far above the contact time step, with a small inner cutoff (c dt / m up to 34 at h_in), the
    # film alone would overshoot explicitly: `limit yes` keeps the approach speed falling
    # monotonically (the film's resistance capped at m / 2 dt), `limit no` blows up.
    def approach(limit):
        return lubrication_run(np_ranks, settle=1, speed=v_start, gap0=h_start, dt=1e-4, steps=75, every=1,
                               limit=limit, inner=0.001, contact=0)
    limited, free = approach("yes"), approach("no")
    closing = limited[:, 1] > 0
    rises = int(np.sum(np.diff(limited[closing, 2]) > 1e-12 * v_start))
    blown = float(np.max(np.abs(free[:, 2]))) / v_start
    report(f"lubrication at dt = 1e-4 s, inner 0.001 a (c dt / m = {6 * math.pi * mu * a / 0.001 * 1e-4 / mass:.0f} "
           f"at h_in): limit yes: approach speed never rises over {int(closing.sum())} steps to contact; "
           f"limit no: |speed| reaches {blown:.2g} v_start")
    assert rises == 0 and np.all(limited[closing, 2] > 0) and blown > 3    # the drive alone gives v_start


# Measured low-Re exponents n of u / u_t = (1 - phi)^n: Richardson & Zaki (1954) 4.65, Garside &
# Al-Dibouni (1977) 5.1. Each hindrance is held to the data it was fitted to (Di Felice's to
# Richardson & Zaki's): within 5 % of the measured speed ratio over phi = 0.01-0.4.
MEASURED_EXPONENT = {"difelice": 4.65, "richardson-zaki": 4.65, "garside": 5.1}
HINDRANCE_CASES = (("difelice", "none"), ("standard", "richardson-zaki"), ("dallavalle", "richardson-zaki"),
                   ("stokes", "garside"), ("standard", "difelice"))


@check
def hindered_settling(np_ranks: int):
    # Validation case G: a uniform suspension settles at u_t (1 - phi)^n at low Re.
    for law, hindrance in HINDRANCE_CASES:
        name = "law difelice (Bravo et al.)" if law == "difelice" else f"{law} + {hindrance}"
        model = _core.DragModel(law, 1000.0, 1e-3, hindrance=hindrance)
        d = 2e-5
        weight = 1650.0 * G * math.pi / 6 * d ** 3
        clear = model.steady_speed(d, weight)[0]
        measured_n = MEASURED_EXPONENT["difelice" if law == "difelice" else hindrance]
        for phi in (0.01, 0.1, 0.2, 0.3, 0.4):
            out = run_deck("hindered_settling.lmp", {"phi": phi, "law": law, "hindrance": hindrance}, np_ranks)
            ratio = out.results["hindered"] / out.results["single"]
            model_ratio = model.steady_speed(d, weight, 1 - phi)[0] / clear    # the law's own fixed point
            measured = (1 - phi) ** measured_n
            report(f"case G {name} phi={phi}: u/u_t = {ratio:.4f} (n = {math.log(ratio) / math.log(1 - phi):.3f}), "
                   f"the law's steady ratio {model_ratio:.4f}, measured exponent {measured_n} gives {measured:.4f} "
                   f"({ratio / measured - 1:+.2%}); grid fraction {out.results['phi']:.6f}")
            assert abs(out.results["phi"] - phi) < 1e-9
            assert abs(ratio / model_ratio - 1) < 2e-3     # 50 steps of 1e-3 s: 70 relaxation times
            assert abs(ratio / measured - 1) < 0.05
            # Mixture-density buoyancy (eps times the net weight) with the hindrance's mixture form must
            # give the same settling velocity as plain buoyancy.
            if phi in (0.1, 0.4):
                mixed = run_deck("hindered_settling.lmp", {"phi": phi, "law": law, "hindrance": hindrance,
                                                           "buoyancy": "mixture"}, np_ranks)
                rel = abs(mixed.results["hindered"] / out.results["hindered"] - 1)
                report(f"case G {name} phi={phi}: mixture buoyancy vs plain: relative difference {rel:.1e}")
                assert rel < 1e-10


# ---- the plugin route (an lmp built with the PLUGIN package) -----------------------------------------------
# What the plugin must list: the styles the package's headers declare (style_table.py checks the
# registration table against them).
PLUGIN_STYLES = {(kind.lower(), name) for kind, name, _ in declared_styles()}


@check(ranks=None)
def plugin_styles(np_ranks: int):
    """Every SEDIMENT style comes from sedimentplugin.so (`plugin list`), loaded by `plugin load` (with
    SEDIMENT_PLUGIN naming it: the harness's wrapper deck) or at start (with LAMMPS_PLUGIN_PATH naming
    its folder, on releases that load from there)."""
    import re

    source = os.environ.get("SEDIMENT_PLUGIN") or os.environ.get("LAMMPS_PLUGIN_PATH")
    if not source:
        raise RuntimeError("plugin_styles needs SEDIMENT_PLUGIN (sedimentplugin.so, loaded by `plugin load`) or "
                           "LAMMPS_PLUGIN_PATH (its folder, loaded at start)")
    with tempfile.TemporaryDirectory() as tmp:
        deck = Path(tmp) / "plugins.lmp"
        deck.write_text("plugin list\n")
        out = run_deck(deck, {}, np_ranks, cwd=Path(tmp))
    listed = set(re.findall(r"^\s*\d+: (\w+) style plugin (\S+)$", out.text, re.MULTILINE))
    how = "plugin load" if os.environ.get("SEDIMENT_PLUGIN") else "LAMMPS_PLUGIN_PATH"
    report(f"plugin: {len(listed)} styles loaded from {source} ({how}): "
           f"{', '.join(sorted(f'{k} {n}' for k, n in listed))}")
    assert listed == PLUGIN_STYLES, listed ^ PLUGIN_STYLES


# ---- every style: pinned regression, restart and time-step-change replay (tests/decks/styles.py) --------
for _scene in styles.SCENES:
    CHECKS[f"style_{_scene.name}"] = (lambda np_ranks, scene=_scene, **kw: styles.check_scene(scene, np_ranks, **kw),
                                      (1, 2))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("name", nargs="?", choices=sorted(CHECKS))
    parser.add_argument("--np", type=int, default=1, help="MPI ranks")
    parser.add_argument("--list", action="store_true", help="print each check with the rank counts ctest runs it "
                        "with (none: it compares rank counts itself) and exit")
    parser.add_argument("--regenerate", action="store_true", help="style_* checks: pin the reference anew")
    args = parser.parse_args()
    if args.list:
        for name, (_, ranks) in sorted(CHECKS.items()):
            if ranks is not None:
                print(name, *ranks)
        return
    if args.name is None:
        parser.error("name a check (or --list)")
    if _core is None:
        raise _core_missing
    function = CHECKS[args.name][0]
    function(args.np, regenerate=True) if args.regenerate else function(args.np)
    print(f"PASS {args.name} np={args.np}")


if __name__ == "__main__":
    main()
