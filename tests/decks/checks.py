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
import shutil
import tempfile
from pathlib import Path

import numpy as np

import styles
from harness import HERE, report, run_batch, run_deck

try:    # (the harness puts python/ on the path)
    from sediment import _core
except ImportError as not_built:    # listing the checks, at configure time before the build, needs none
    _core, _core_missing = None, not_built

G = 9.81
DATA = HERE.parent / "data"    # the validation data the checks compare with (tests/data)
# name -> (function of the rank count, rank counts ctest runs it with: () once without --np; None:
# not in the standard list, registered by tests/decks/CMakeLists.txt for a LAMMPS with PLUGIN only)
CHECKS: dict = {}


def check(fn=None, *, ranks=(1, 2)):
    """Registers a check; ctest asks `checks.py --list` for the names and their rank counts."""
    def register(fn):
        CHECKS[fn.__name__] = (fn, None if ranks is None else tuple(ranks))
        return fn
    return register(fn) if fn is not None else register


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


# ---- concentration grid ------------------------------------------------------------------------
@check
def concentration_grid(np_ranks: int):
    with tempfile.TemporaryDirectory() as tmp:
        profile, cells, peratom = (Path(tmp) / name for name in ("profile.txt", "cells.txt", "peratom.txt"))
        run_deck("concentration_grid.lmp", {"profile": profile, "cells": cells, "peratom": peratom}, np_ranks)
        table = np.loadtxt(profile, comments="#", skiprows=4)[:, 1:]    # drop the row index
        grid = np.loadtxt(cells, comments="#", skiprows=4)[:, 1:]
        atoms = np.loadtxt(peratom, skiprows=9)
    z, total, classes, types = table[:, 0], table[:, 1], table[:, 2:5], table[:, 5:7]
    cell = 0.01 * 0.01 * (0.02 / 80)
    solid = float(np.sum(4 / 3 * np.pi * atoms[:, 2] ** 3))
    conserved = abs(total.sum() * cell - solid) / solid
    report(f"concentration grid: {len(atoms)} spheres, 80 layers; solid volume conserved to {conserved:.1e}; "
           f"classes sum to total within {np.max(np.abs(classes.sum(axis=1) - total)):.1e}, "
           f"types within {np.max(np.abs(types.sum(axis=1) - total)):.1e}; mean fraction {total.mean():.5f}")
    assert conserved < 1e-12
    assert np.allclose(classes.sum(axis=1), total, rtol=0, atol=1e-14)
    assert np.allclose(types.sum(axis=1), total, rtol=0, atol=1e-14)
    # type 2 holds a quarter of the spheres; per-atom values interpolate the total profile
    assert 0.15 < types[:, 1].sum() / total.sum() < 0.35
    interp = np.interp(atoms[:, 1], z, total)
    inside = (atoms[:, 1] > z[0]) & (atoms[:, 1] < z[-1])
    assert np.allclose(atoms[inside, 3], interp[inside], rtol=1e-12, atol=0)

    # 3d cells (x fastest): x y z centres, then the same columns. Summed over x and y they must give
    # the layers (exact slab volumes, an independent formula); fractions conserve the solid volume.
    fractions = grid[:, 3:].reshape(80, 25, 25, 6)
    as_layers = fractions.mean(axis=(1, 2))
    layer_diff = float(np.max(np.abs(as_layers - table[:, 1:])))
    conserved_cells = abs(fractions[..., 0].sum() * cell / 625 - solid) / solid
    # per-atom: periodic trilinear interpolation between cell centres
    def bracket(x, h, n):
        s = x / h - 0.5
        k = np.floor(s).astype(int)
        return k % n, (k + 1) % n, s - k
    (x0, x1, wx), (y0, y1, wy), (z0, z1, wz) = (bracket(atoms[:, col], h, n) for col, h, n in
                                                ((4, 0.01 / 25, 25), (5, 0.01 / 25, 25), (1, 0.02 / 80, 80)))
    total_cells = fractions[..., 0]
    interp_cells = sum(total_cells[zk, yk, xk] * (wz if zu else 1 - wz) * (wy if yu else 1 - wy) * (wx if xu else 1 - wx)
                       for zu, zk in ((0, z0), (1, z1)) for yu, yk in ((0, y0), (1, y1)) for xu, xk in ((0, x0), (1, x1)))
    interp_err = float(np.max(np.abs(atoms[:, 6] - interp_cells)))
    report(f"concentration grid, 25 x 25 x 80 cells: solid volume conserved to {conserved_cells:.1e}; cells summed over "
           f"x, y match the layers within {layer_diff:.1e} (fraction); per-atom trilinear within {interp_err:.1e}; "
           f"max cell fraction {total_cells.max():.3f}")
    assert conserved_cells < 1e-12 and layer_diff < 1e-13 and interp_err < 1e-13


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


@check
def concentration_every(np_ranks: int):
    # With 'every N' the per-atom fractions follow the atoms every step but read the field of the
    # last refresh: on refresh steps they equal a run refreshing every step, in between they are the
    # last refresh's profile interpolated at the atoms' current heights.
    with tempfile.TemporaryDirectory() as tmp:
        files = {n: {k: Path(tmp) / f"{k}{n}.txt" for k in ("profile", "peratom")} for n in (1, 5)}
        for every, paths in files.items():
            run_deck("concentration_every.lmp", {"every": every, **paths}, np_ranks)
        frames = {n: read_dump_frames(files[n]["peratom"]) for n in files}
        profiles = read_profile_blocks(files[5]["profile"])
    stale = 0.0
    for step, atoms in frames[5].items():
        fresh = frames[1][step]
        if step % 5 == 0:
            assert np.array_equal(atoms[:, 2], fresh[:, 2]), f"step {step}: a refresh step differs from every 1"
            continue
        z, total = profiles[step - step % 5]
        # the field is periodic along z: interpolate across the ends as the compute does
        period = 0.02
        zz = np.concatenate([z - period, z, z + period])
        expected = np.interp(atoms[:, 1], zz, np.tile(total, 3))
        assert np.allclose(atoms[:, 2], expected, rtol=1e-12, atol=1e-15), f"step {step}: not the step {step - step % 5} field"
        stale = max(stale, float(np.max(np.abs(atoms[:, 2] - fresh[:, 2]))))
    report(f"concentration grid every 5: refresh steps equal to every 1; in between the last field at the new "
           f"heights, differing from a fresh field by up to {stale:.2e}")
    assert stale > 0.0    # the spheres move: a field refreshed every step would differ


def read_dump_frames(path: Path) -> dict[int, np.ndarray]:
    """The frames of a LAMMPS text dump (columns after the header) by step."""
    lines = path.read_text().splitlines()
    frames, k = {}, 0
    while k < len(lines):
        step = int(lines[k + 1])
        count = int(lines[k + 3])
        start = k + 9
        frames[step] = np.array([[float(v) for v in line.split()] for line in lines[start:start + count]])
        k = start + count
    return frames


def read_profile_blocks(path: Path) -> dict[int, tuple[np.ndarray, np.ndarray]]:
    """Layer centres and total fraction of each block of a fix ave/time vector file, by step."""
    blocks, rows, step, left = {}, [], None, 0
    for line in path.read_text().splitlines():
        if line.startswith("#") or not line.strip():
            continue
        values = line.split()
        if left == 0:
            step, left, rows = int(values[0]), int(values[1]), []
            continue
        rows.append([float(v) for v in values[1:3]])
        left -= 1
        if left == 0:
            table = np.array(rows)
            blocks[step] = (table[:, 0], table[:, 1])
    return blocks


# ---- layer files -------------------------------------------------------------------------------
EXAMPLES = HERE.parents[1] / "examples"


@check
def layers_hdf5(np_ranks: int):
    from sediment.sim.layers import read_layers

    deck = EXAMPLES / "polydisperse" / "in.polydisperse"
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        solid = run_deck(deck, {"tend": 2.0, "file": tmp / "whole.h5"}, np_ranks, cwd=tmp).results["solid_volume"]
        run_deck(deck, {"tend": 1.0, "file": tmp / "split.h5", "restart": 1,
                                    "restart_file": tmp / "poly.restart"}, np_ranks, cwd=tmp)
        shutil.copy(tmp / "split.h5", tmp / "cut.h5")
        run_deck("layers_restart.lmp", {"restart": tmp / "poly.restart", "file": tmp / "split.h5"}, np_ranks, cwd=tmp)
        # Cut short at step 170 after a restart file at step 160: the frame of step 150 was still
        # waiting to be written when a restart file came due, and a resumed run continues after it.
        cut = run_deck("layers_restart.lmp", {"restart": tmp / "poly.restart", "file": tmp / "cut.h5",
                                              "cut_at": 170, "restart_every": 80, "cut_restart": tmp / "cut.restart"},
                       np_ranks, expect_failure=True, cwd=tmp)
        assert "Fix halt condition" in cut.text
        left = read_layers(tmp / "cut.h5.partial")
        run_deck("layers_restart.lmp", {"restart": tmp / "cut.restart.160", "file": tmp / "cut.h5"}, np_ranks, cwd=tmp)
        whole, split, resumed = (read_layers(tmp / f"{name}.h5") for name in ("whole", "split", "cut"))
        serial = None
        if np_ranks > 1:
            run_deck(deck, {"tend": 2.0, "file": tmp / "serial.h5"}, 1, cwd=tmp)
            serial = read_layers(tmp / "serial.h5")
    conservation = float(np.max(np.abs(whole.solid_volume() / solid - 1)))
    classes = whole.fraction[:, :, 1:].sum(axis=2)
    report(f"layers/hdf5: {len(whole.time)} frames at t = {whole.time.tolist()}; solid volume conserved to "
           f"{conservation:.1e}; split run (restart at 1 s) frames {split.step.tolist()}")
    assert whole.step.tolist() == [0, 50, 100, 150, 200]
    assert conservation < 1e-12
    assert np.allclose(classes, whole.total, rtol=0, atol=1e-12)
    assert split.step.tolist() == whole.step.tolist()
    diff = float(np.max(np.abs(split.fraction - whole.fraction)))
    report(f"restart: split run vs whole run max difference of the layer fractions {diff:.1e}")
    assert diff < 1e-12
    report(f"cut at step 170 (restart file at 160): frames left {left.step.tolist()}; resumed frames "
           f"{resumed.step.tolist()}")
    assert left.step.tolist() == [0, 50, 100, 150] and not left.complete
    assert resumed.step.tolist() == whole.step.tolist()
    cut_diff = float(np.max(np.abs(resumed.fraction - whole.fraction)))
    report(f"cut and resumed vs whole run: max difference of the layer fractions {cut_diff:.1e}")
    assert cut_diff < 1e-12
    if serial is not None:
        rank_diff = float(np.max(np.abs(serial.fraction - whole.fraction)))
        report(f"1 vs {np_ranks} ranks: max difference of the layer fractions {rank_diff:.1e}")
        assert rank_diff < 1e-12


@check
def restart_state(np_ranks: int):
    """2N steps in one run vs N steps + write_restart + read_restart in a new process + N steps."""
    from sediment.sim.layers import read_layers

    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        run_deck("restart_state.lmp", {"phase": "whole", "state": tmp / "whole.dump", "layers": tmp / "whole.h5"},
                 np_ranks, cwd=tmp)
        run_deck("restart_state.lmp", {"phase": "first", "restart": tmp / "pile.restart", "layers": tmp / "split.h5"},
                 np_ranks, cwd=tmp)
        run_deck("restart_state.lmp", {"phase": "second", "restart": tmp / "pile.restart", "state": tmp / "split.dump",
                                       "layers": tmp / "split.h5"}, np_ranks, cwd=tmp)
        whole, split = np.loadtxt(tmp / "whole.dump", skiprows=9), np.loadtxt(tmp / "split.dump", skiprows=9)
        frames_whole, frames_split = read_layers(tmp / "whole.h5"), read_layers(tmp / "split.h5")
    assert whole.shape == split.shape and np.array_equal(whole[:, 0], split[:, 0])
    scale = {"position": 1e-3, "velocity": np.abs(whole[:, 4:7]).max(), "spin": np.abs(whole[:, 7:10]).max()}
    diffs = {name: float(np.abs(whole[:, cols] - split[:, cols]).max() / scale[name])
             for name, cols in (("position", slice(1, 4)), ("velocity", slice(4, 7)), ("spin", slice(7, 10)))}
    layer_diff = float(np.max(np.abs(frames_whole.fraction - frames_split.fraction)))
    report(f"restart: {len(whole)} spheres with contacts, drag and the grid; split vs whole max difference "
           f"(relative to d, max speed, max spin): {', '.join(f'{k} {v:.1e}' for k, v in diffs.items())}; "
           f"layer frames {frames_split.step.tolist()} vs {frames_whole.step.tolist()}, fractions {layer_diff:.1e}")
    assert all(v < 1e-9 for v in diffs.values())
    assert frames_split.step.tolist() == frames_whole.step.tolist() == list(range(0, 3001, 500))
    assert layer_diff < 1e-12


# ---- two-way coupling: fix fluid/flow ------------------------------------------------------------
CLOUD_DECK = HERE.parents[1] / "examples" / "falling_cloud" / "in.falling_cloud"


def cloud_result(np_ranks: int, tmp: Path, **variables) -> dict:
    out = run_deck(CLOUD_DECK, variables, np_ranks, cwd=tmp)
    line = next(line for line in out.text.splitlines() if line.startswith("RESULT "))
    words = line.split()[1:]
    return {key: float(value) for key, value in zip(words[::2], words[1::2])}


@check
def falling_cloud(np_ranks: int):
    """A spherical cloud of N spheres settles for N a / R >> 1 as a drop, U = U_s (1 + 6/5 N a / R)
    (Nitsche & Batchelor 1997), in the periodic box less Hasimoto's return flow, -2.837 N a U_s / L:
    the example deck, for N a / R = 5, 20 and 50 (a = R / 100: a dilute cloud, 0.5 % solids at most).
    The kernel's Gaussian (sigma = one cell) smooths the cloud's edge and its pair interactions, which
    slows it by about 2.3 (sigma / R)^2 (measured at R / sigma = 4, 6, 8, 12: 13.6, 6.5, 3.6, 1.3 %);
    the check extrapolates R / sigma = 4 and 6 (32 and 48 cells, box L = 8 R) to sigma -> 0 as
    (sigma / R)^2 and asks that within 3 % of the prediction: what remains is the random cloud's
    own spread (one seed), O((R / L)^3) = 0.4 % of the box and the O(a / d) discreteness."""
    worst = 0.0
    with tempfile.TemporaryDirectory() as tmp:
        for n, na_r in ((500, 5), (2000, 20), (5000, 50)):
            coarse = cloud_result(np_ranks, Path(tmp), n=n, na_r=na_r, cells=32)
            fine = cloud_result(np_ranks, Path(tmp), n=n, na_r=na_r, cells=48)
            extrapolated = fine["speed"] + (fine["speed"] - coarse["speed"]) / (1.5 ** 2 - 1)
            ratio = extrapolated / fine["predicted"]
            report(f"cloud N={n} Na/R={na_r}: U/U_s {coarse['speed'] / fine['us']:.3f} (R/sigma 4), "
                   f"{fine['speed'] / fine['us']:.3f} (R/sigma 6), extrapolated {extrapolated / fine['us']:.3f}; "
                   f"Nitsche & Batchelor {fine['drop'] / fine['us']:.3f}, with the box's return flow "
                   f"{fine['predicted'] / fine['us']:.3f}: ratio {ratio:.4f}; largest mean u_z over a plane "
                   f"{fine['flux']:.1e} m/s (grid's largest {fine['peak']:.1e})")
            worst = max(worst, abs(ratio - 1))
            # converging from below (the smoothing slows the cloud), and no net flux through any plane
            assert coarse["speed"] < fine["speed"] < 1.03 * fine["predicted"]
            assert abs(ratio - 1) < 0.03
            assert fine["flux"] < 1e-12 * fine["peak"] and coarse["flux"] < 1e-12 * coarse["peak"]
    report(f"falling cloud: worst extrapolated speed {worst:.2%} off the prediction")


def flow_data(path: Path, positions: np.ndarray, types: np.ndarray, box: tuple[float, float, float]) -> None:
    n = len(positions)
    atoms = np.column_stack([np.arange(1, n + 1), types, np.full(n, 2e-4), np.full(n, 1100.0), positions])
    with open(path, "w") as f:
        f.write(f"settling cloud\n\n{n} atoms\n2 atom types\n\n0 {box[0]} xlo xhi\n0 {box[1]} ylo yhi\n"
                f"0 {box[2]} zlo zhi\n\nAtoms # sphere\n\n")
        np.savetxt(f, atoms, fmt=["%d", "%d", "%.17g", "%.17g", "%.17g", "%.17g", "%.17g"])


def cloud_positions(n: int, centre: tuple[float, float, float], radius: float, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    points = rng.uniform(-1, 1, (4 * n, 3))
    points = points[np.einsum("ij,ij->i", points, points) < 1][:n]
    return np.asarray(centre) + radius * points


@check
def flow_column_mirror(np_ranks: int):
    """The closed column (free slip at bottom and top by mirror images) is the periodic box twice as
    tall holding the spheres and their mirror images (which rise): the same state to round-off. The
    cloud sits near the bottom, so the bottom's image matters (it slows the cloud)."""
    height, side = 0.016, 0.016
    real = cloud_positions(300, (side / 2, side / 2, 0.25 * height), 0.003, 7)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        flow_data(tmp / "column.data", real, np.ones(len(real)), (side, side, height))
        mirrored = real * [1, 1, -1] + [0, 0, 2 * height]
        flow_data(tmp / "mirror.data", np.vstack([real, mirrored]), np.r_[np.ones(len(real)), 2 * np.ones(len(real))],
                  (side, side, 2 * height))
        states = {}
        for mode in ("column", "mirror", "periodic"):
            data = tmp / ("column.data" if mode != "mirror" else "mirror.data")
            if mode == "periodic":    # the same cloud in a periodic box as tall as the column
                flow_data(tmp / "periodic.data", real, np.ones(len(real)), (side, side, height))
                data = tmp / "periodic.data"
            run_deck("fluid_flow.lmp", {"data": data, "mode": mode, "state": tmp / f"{mode}.txt", "phase": "whole"},
                     np_ranks, cwd=tmp)
            states[mode] = np.loadtxt(tmp / f"{mode}.txt", skiprows=9)
    column, mirror, periodic = states["column"], states["mirror"][: len(real)], states["periodic"]
    scale = np.abs(column[:, 4:10]).max()
    diff = float(np.abs(column[:, 4:10] - mirror[:, 4:10]).max() / scale)
    images = states["mirror"][len(real):]
    image_vz = float(images[:, 6].mean())
    report(f"column vs its explicit mirror image, {len(real)} spheres: max difference in v and u {diff:.1e} "
           f"(of {scale:.2e} m/s); mean v_z: column {column[:, 6].mean():.4e}, images {image_vz:.4e} (rising), "
           f"periodic box {periodic[:, 6].mean():.4e} m/s")
    assert diff < 1e-9
    assert abs(image_vz + column[:, 6].mean()) < 1e-9 * scale
    # the bottom slows the cloud against the periodic box of the same height
    assert column[:, 6].mean() > periodic[:, 6].mean()


@check
def flow_restart(np_ranks: int):
    """2N steps in one run vs N steps + write_restart + read_restart in a new process + N steps: the
    per-atom fluid velocity comes back with the restart, so the flow carries on as if never stopped."""
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        flow_data(tmp / "cloud.data", cloud_positions(400, (0.008, 0.008, 0.008), 0.003, 3), np.ones(400),
                  (0.016, 0.016, 0.016))
        common = {"data": tmp / "cloud.data", "restart": tmp / "flow.restart"}
        run_deck("fluid_flow.lmp", {**common, "phase": "whole", "state": tmp / "whole.txt"}, np_ranks, cwd=tmp)
        run_deck("fluid_flow.lmp", {**common, "phase": "first"}, np_ranks, cwd=tmp)
        run_deck("fluid_flow.lmp", {**common, "phase": "second", "state": tmp / "split.txt"}, np_ranks, cwd=tmp)
        whole, split = np.loadtxt(tmp / "whole.txt", skiprows=9), np.loadtxt(tmp / "split.txt", skiprows=9)
    scale = np.abs(whole[:, 4:10]).max()
    diff = float(np.abs(whole[:, 1:] - split[:, 1:]).max())
    report(f"flow restart: {len(whole)} spheres, split vs whole max difference {diff:.1e} (speeds up to {scale:.1e} m/s)")
    assert whole.shape == split.shape and diff <= 1e-12 * max(scale, 1e-3)


@check(ranks=())
def flow_ranks(np_ranks: int):
    """The falling cloud on 1 and 2 ranks: the same speed to round-off (the reduce-scatter and the
    FFT's remaps sum in another order)."""
    with tempfile.TemporaryDirectory() as tmp:
        one, two = (cloud_result(ranks, Path(tmp), n=1000, cells=32)["speed"] for ranks in (1, 2))
    report(f"cloud speed on 1 rank {one!r}, on 2 ranks {two!r}: relative difference {abs(one - two) / one:.1e}")
    assert abs(one - two) < 1e-10 * one


# ---- numerical guards and lost atoms ---------------------------------------------------------
GUARD_SCENE = """units si
atom_style sphere
atom_modify map array
boundary p p f
region box block -0.01 0.01 -0.01 0.01 -0.05 0.05
create_box 1 box
create_atoms 1 single 0 0 0.01
create_atoms 1 single 0.005 0 -0.01
set atom * diameter 1e-3 density 2500
comm_modify cutoff 0.001
fix grav all gravity 9.81 vector 0 0 -1
fix water all fluid density 1000 viscosity 1e-3 surface z 0
fix buoy all fluid/buoyancy water
"""


def guard_deck(tmp: Path, name: str, body: str) -> Path:
    deck = tmp / f"{name}.lmp"
    deck.write_text(GUARD_SCENE + body + "\n")
    return deck


@check
def guards(np_ranks: int):
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        # A sphere in the air above the free surface: counted, and it falls exactly as under nve/sphere.
        out = run_deck(guard_deck(tmp, "outside", """fix drag all fluid/drag water law stokes
fix step all nve/sphere/fluid
timestep 1e-4
run 10
print "RESULT outside $(f_step[3]) stuck $(f_step[1]) capped $(f_step[4]) vz1 $(vz[1]:%.17g) vz2 $(vz[2]:%.17g)"
"""), {}, np_ranks, cwd=tmp)
        r = out.results
        report(f"guards: outside-the-fluid count {r['outside']:.0f}; the sphere in the air falls at {r['vz1']:.17g} m/s "
               f"(g t = {-G * 1e-3:.17g}), the immersed one at {r['vz2']:.6g}")
        assert r["outside"] == 1 and r["stuck"] == 0 and r["capped"] == 0
        assert abs(r["vz1"] + G * 1e-3) < 1e-15 and -G * 1e-3 < r["vz2"] < 0
        # The same spheres integrated explicitly: fluid/drag counts its own.
        out = run_deck(guard_deck(tmp, "explicit", """set atom 2 diameter 1e-4 density 2500
fix drag all fluid/drag water law stokes
fix step all nve/sphere
timestep 1e-2
run 1
print "RESULT unstable $(f_drag[4]) outside $(f_drag[5])"
"""), {}, np_ranks, cwd=tmp)
        report(f"guards: explicit drag at dt = 0.01 s (tau of the immersed sphere 1.4 ms): {out.results['unstable']:.0f} sphere(s) with dt > 2 tau, "
               f"{out.results['outside']:.0f} outside the fluid")
        assert out.results == {"unstable": 1.0, "outside": 1.0}
        assert "have dt > 2 tau under explicit drag" in out.text
        # Local solid fraction above max_fraction: counted, drag evaluated at the cap.
        out = run_deck(guard_deck(tmp, "capped", """compute conc all concentration/grid layers z 10 bounds -0.05 0.05
fix drag all fluid/drag water law difelice concentration c_conc max_fraction 1e-6
fix step all nve/sphere/fluid
timestep 1e-4
run 2
print "RESULT capped $(f_step[4]) outside $(f_step[3])"
"""), {}, np_ranks, cwd=tmp)
        report(f"guards: local fraction above max_fraction 1e-6: {out.results['capped']:.0f} sphere(s)")
        assert out.results == {"capped": 1.0, "outside": 1.0}
        # A force that overflows: stopped at once, naming the atom, instead of NaN spreading; on every
        # path of the step: no fluid/drag at all, a sphere in the air (atom 1) and one in the water
        # (atom 2) under the linear and the blocked smooth step.
        for name, drag, pushed in (("bare", "", 1), ("stokes", "fix drag all fluid/drag water law stokes", 1),
                                   ("stokes_immersed", "fix drag all fluid/drag water law stokes", 2),
                                   ("dallavalle", "fix drag all fluid/drag water law dallavalle", 2)):
            out = run_deck(guard_deck(tmp, f"overflow_{name}", f"""{drag}
fix step all nve/sphere/fluid
group pushed id {pushed}
fix push pushed addforce 0 0 1e308
timestep 1e-4
run 10
"""), {}, np_ranks, expect_failure=True, cwd=tmp)
            assert f"Fix nve/sphere/fluid: atom {pushed} has a non-finite position or velocity at step 1" in out.text, \
                f"overflow on the {name} path not caught:\n{out.text[-2000:]}"
        # A NaN force pressing a grain that rests on the floor (atom 2 sits on it from the start): not
        # taken for a grain at rest, nor put back on the floor, but stopped at once.
        for law in ("stokes", "dallavalle"):
            out = run_deck(guard_deck(tmp, f"nan_at_rest_{law}", f"""fix drag all fluid/drag water law {law}
fix step all nve/sphere/fluid floor z -0.0105
timestep 1e-3
run 20
print "RESULT z2 $(z[2]:%.17g) vz2 $(vz[2])"
variable nan equal (1e308*10)-(1e308*10)
group resting id 2
fix push resting addforce 0 0 v_nan
run 20
"""), {}, np_ranks, expect_failure=True, cwd=tmp)
            assert out.results == {"z2": -0.01, "vz2": 0.0}, out.results
            assert "Fix nve/sphere/fluid: atom 2 has a non-finite position or velocity at step 21" in out.text, \
                f"a NaN force on a grain at rest under {law} not caught:\n{out.text[-2000:]}"
        # Spheres leaving the box: LAMMPS's lost-atom policy applies, the fixes carry on with the rest.
        leave = """fix drag all fluid/drag water law stokes
fix step all nve/sphere/fluid
velocity all set 0 0 0
set atom 1 vz 30
timestep 1e-4
thermo_style custom step atoms f_step[3]
thermo 10
{policy}
run 100
print "RESULT atoms $(atoms) outside $(f_step[3])"
"""
        out = run_deck(guard_deck(tmp, "lost_ignore", leave.format(policy="thermo_modify lost ignore")), {}, np_ranks,
                       cwd=tmp)
        report(f"guards: a sphere shot out of the box with 'lost ignore': {out.results['atoms']:.0f} atom left, "
               f"{out.results['outside']:.0f} outside the fluid")
        assert out.results == {"atoms": 1.0, "outside": 0.0}
        out = run_deck(guard_deck(tmp, "lost_error", leave.format(policy="")), {}, np_ranks, expect_failure=True,
                       cwd=tmp)
        assert "ERROR: Lost atoms: original 2 current 1" in out.text


# ---- bad input ----------------------------------------------------------------------------------
# Current LAMMPS refuses numbers beyond the double range in utils::numeric itself, before the style
# sees them; LAMMPS 2021 turns them into inf, which the style refuses.
OUT_OF_RANGE = "is out of range"
ONE_SPHERE = "create_atoms 1 single 0.5 0.5 0.5\nset atom 1 diameter 1e-3 density 2500\n"
FLOW = "fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f law stokes\n"
BAD_INPUT = [
    ("fix f all fluid density -1 viscosity 1e-3", "density must be finite and > 0"),
    ("fix f all fluid density 1e400 viscosity 1e-3", ("density must be finite and > 0", OUT_OF_RANGE)),
    ("fix f all fluid density 1000 viscosity 0", "viscosity must be finite and > 0"),
    ("fix f all fluid density 1000 viscosity 1e999", ("viscosity must be finite and > 0", OUT_OF_RANGE)),
    ("fix f all fluid density 1000 viscosity nan", "Expected floating point parameter"),
    ("fix f all fluid density 1000 viscosity 1e-3 surface plane 0 0 0 0 0 0", "normal must be finite and non-zero"),
    ("fix f all fluid density 1000", "give exactly one of 'viscosity MU' or 'bingham TAU_Y ETA_B'"),
    ("fix f all fluid viscosity 1e-3", "keyword 'density' is required"),
    ("fix f all fluid density 1000 viscosity 1e-3 colour red", "unknown keyword 'colour'"),
    ("fix f all fluid density 1000 bingham -3 0.1", "bingham yield stress must be finite and > 0"),
    ("fix f all fluid density 1000 bingham 3 -0.1", "bingham plastic viscosity must be finite and > 0"),
    ("fix f all fluid density 1000 viscosity 1e-3 surface w 0", "surface axis must be x, y, z or plane"),
    ("fix f all fluid density 1000 viscosity 1e-3 surface z v_nolevel\nrun 0", "surface variable 'nolevel' does not exist"),
    ("variable h atom z\nfix f all fluid density 1000 viscosity 1e-3 surface z v_h\nrun 0", "surface variable 'h' must be equal-style"),
    ("fix f all fluid density 1000 viscosity 1e-3 surface z 0 crossing middle", "crossing must be cap or centre, not 'middle'"),
    ("fix f all fluid density 1000 viscosity 1e-3 crossing centre", "keyword 'crossing' needs a 'surface'"),
    ("fix f all fluid density 1000 viscosity", "keyword 'viscosity' needs 1 value"),
    ("fix f all fluid density abc viscosity 1e-3", "Expected floating point parameter"),
    ("fix f all fluid density 1000 viscosity 1e-3 region nowhere\nrun 0", "region 'nowhere' does not exist"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f law stoke", "unknown law 'stoke'"),
    ("fix d all fluid/drag nofluid law stokes\nrun 0", "fluid fix 'nofluid' does not exist"),
    ("fix d all fluid/drag grav law stokes\nrun 0", "fix 'grav' is a fix gravity, not a fix fluid"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f", "expected 'fix ID group fluid/drag FLUID-ID law NAME'"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f rotation yes", "keyword 'law' is required"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f law stokes rotation maybe", "rotation must be yes or no"),
    ("unfix grav\nfix f all fluid density 1000 viscosity 1e-3\nfix b all fluid/buoyancy f\nrun 0", "needs a fix gravity"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix b all fluid/buoyancy f gravity f\nrun 0", "is a fix fluid, not a fix gravity"),
    ("fix n all nve/sphere/fluid extra", "unknown keyword 'extra' (expected floor)"),
    ("fix n all nve/sphere/fluid floor z", "'floor' needs an axis and a coordinate"),
    ("fix n all nve/sphere/fluid floor w 0", "floor axis must be x, y or z, not 'w'"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix b all fluid/buoyancy f mixture c_c", "'mixture' needs c_ID and the solid density"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix b all fluid/buoyancy f mixture c_c -5", "mixture solid density must be finite and > 0"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix b all fluid/buoyancy f mixture c_c 2650\nrun 0", "compute 'c' does not exist"),
    ("pair_style lubricate/fluid", "needs the ID of a fix fluid"),
    ("pair_style lubricate/fluid w inner 0.5 outer 0.1", "need 0 < inner < outer"),
    ("pair_style lubricate/fluid w squeeze 2", "unknown keyword 'squeeze'"),
    ("pair_style lubricate/fluid w limit maybe", "limit must be yes or no, not 'maybe'"),
    ("pair_style lubricate/fluid w repulsion -1", "repulsion force scale must be finite and > 0"),
    ("pair_style lubricate/fluid w\npair_coeff * * 1.0", "pair_coeff takes the two types only"),
    ("fix w all fluid density 1000 viscosity 1e-3\npair_style lubricate/fluid w\npair_coeff * *\nrun 0",
     "use 'comm_modify vel yes'"),
    ("comm_modify vel yes\npair_style lubricate/fluid nowater\npair_coeff * *\nrun 0", "Pair lubricate/fluid: fluid fix 'nowater' does not exist"),
    ("compute o all contact/overlap every", "unknown keyword 'every'"),
    ("compute o all contact/overlap\nthermo_style custom c_o\nrun 0", "needs a pair style"),
    ("compute c all concentration/grid", "the grid is required: 'layers AXIS N' or 'cells NX NY NZ'"),
    ("compute c all concentration/grid cells 4 4", "'cells' needs 3 counts in a 3d simulation"),
    ("compute c all concentration/grid cells 4 4 4 bounds 0 1 0 1", "'bounds' needs 6 values (xlo xhi ylo yhi zlo zhi)"),
    ("compute c all concentration/grid cells 4 4 4 layers z 3", "give either 'layers' or 'cells', once"),
    ("compute c all concentration/grid cells 4 4 4\nfix l all layers/hdf5 10 a.h5 c_c\nrun 0", "bins into 3d cells"),
    ("compute c all concentration/grid layers w 10", "layer axis must be x, y or z"),
    ("compute c all concentration/grid layers z 0", "layers count 0 must be from 1 to 200000000"),
    ("compute c all concentration/grid layers z 2000000000", "layers count 2000000000 must be from 1 to 200000000"),
    ("compute c all concentration/grid layers z 3000000000", "layers count 3000000000 must be from 1 to 200000000"),
    ("compute c all concentration/grid cells 1000 1000 1000", "columns is more than 2e+08 values"),
    ("compute c all concentration/grid layers z 10 bounds 1 0", "bounds need LO < HI along z"),
    ("compute c all concentration/grid layers z 10 classes 2 1", "positive and increasing"),
    ("compute c all concentration/grid layers z 10 thickness 1", "'thickness' is for 2d simulations only"),
    ("compute c all concentration/grid layers z 10 smooth -1", "smooth width must be finite and > 0"),
    ("compute c all concentration/grid layers z 10 sieve 3", "unknown keyword 'sieve'"),
    ("compute c all concentration/grid layers z 10 every 0", "every count 0 must be from 1 to"),
    ("compute c all concentration/grid layers z 10 every 2.5", "Expected integer"),
    ("compute c all concentration/grid layers z 10 weight w", "'weight' needs a per-atom property d_NAME"),
    ("compute c all concentration/grid layers z 10 weight d_w\nrun 0", "weight d_w is not a per-atom floating-point vector"),
    ("fix l all layers/hdf5 0 a.h5 c_c", "N must be > 0"),
    ("fix l all layers/hdf5 10 a.h5 conc", "expected a compute reference c_ID"),
    ("fix l all layers/hdf5 10 a.h5 c_nothing\nrun 0", "compute 'nothing' does not exist"),
    ("compute t all temp\nfix l all layers/hdf5 10 a.h5 c_t\nrun 0", "not a compute concentration/grid"),
    ("fix l all layers/hdf5 10 a.h5 c_c colour 1", "unknown keyword 'colour'"),
    ("compute c all concentration/grid layers z 10\nshell echo not hdf5 > notes.h5\nfix l all layers/hdf5 10 notes.h5 c_c\nrun 0", "exists but is not an HDF5 file; not overwriting it"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f law difelice", "law difelice needs keyword 'concentration c_ID'"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f law stokes concentration c_x", "keyword 'concentration' goes with a hindrance"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f law standard hindrance richardson-zaki", "hindrance richardson-zaki needs keyword 'concentration c_ID'"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f law standard hindrance rz concentration c_x", "unknown hindrance 'rz'"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f law zhang-li hindrance difelice concentration c_x", "law zhang-li takes no hindrance difelice"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f law schiller-naumann hindrance garside concentration c_x", "jump in Cd at Re = 1000"),
    ("fix f all fluid density 1000 bingham 10 0.01\nfix d all fluid/drag f law bingham hindrance richardson-zaki concentration c_x", "law bingham takes no hindrance richardson-zaki"),
    ("fix f all fluid density 1000 bingham 10 0.01\nfix d all fluid/drag f law Bingham", "unknown law 'Bingham'"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f law difelice hindrance garside concentration c_x", "law difelice is law dallavalle's drag with hindrance difelice"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f law standart", "unknown law 'standart'"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix b all fluid/buoyancy f max_fraction 1", "max_fraction must be in (0, 1)"),
    # what the styles cannot honour
    (ONE_SPHERE + "fix f all fluid density 1000 viscosity 1e-3\nfix b1 all fluid/buoyancy f\nfix b2 all fluid/buoyancy f\nrun 0",
     "fixes b1 and b2 both give the buoyancy of fluid f to 1 atom(s)"),
    (ONE_SPHERE + "fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f law stokes\ntimestep 0\n"
     "fix s all nve/sphere/fluid\nrun 1", "the timestep must be > 0, not 0"),
    (ONE_SPHERE + "fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f law stokes\ntimestep -0.001\n"
     "fix s all nve/sphere/fluid\nrun 1", "the timestep must be > 0, not -0.001"),
    ("compute c all concentration/grid layers z 10 bounds 2 3\nrun 0", "lie wholly outside the box"),
    # a floor above the grains would lift every one onto it at the first step (and grow a shrink-wrapped box)
    (ONE_SPHERE + "fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f law stokes\ntimestep 1e-4\n"
     "fix s all nve/sphere/fluid floor z 0.9\nrun 1", "floor z 0.9 lies above every sphere (atom 1, the lowest, at z 0.5"),
    ("fix f all fluid density 1000 viscosity 1e-3\ncompute c all concentration/grid layers z 10\n"
     "fix l all layers/hdf5 1 '' c_c", "'' names no file"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f law difelice concentration c_x\nrun 0", "compute 'x' does not exist"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f law difelice concentration c_x buoyancy heavy", "buoyancy must be plain or mixture"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f law difelice concentration c_x max_fraction 1.2", "max_fraction must be in (0, 1)"),
    (FLOW + "fix u all fluid/flow f grid 8 8 8 swirl 1", "Fix fluid/flow: unknown keyword 'swirl'"),
    (FLOW + "fix u all fluid/flow f grid 8 14 8", "Fix fluid/flow: grid size 14 in y is not a product of 2, 3 and 5"),
    (FLOW + "fix u all fluid/flow f grid 8 8", "expected 'fix ID group fluid/flow FLUID-ID grid NX NY NZ"),
    (FLOW + "fix u all fluid/flow f grid 8 8 16\nrun 0", "Fix fluid/flow: the grid's cells must be cubes"),
    (FLOW + "fix u all fluid/flow f grid 8 8 8 brinkman -1", "Fix fluid/flow: brinkman resistance must be >= 0"),
    (FLOW + "fix u all fluid/flow f grid 4 4 4", "Fix fluid/flow: grid size 4 in x is smaller than the kernel's 8 nodes"),
    ("fix f all fluid density 1000 viscosity -1e-3\nfix u all fluid/flow f grid 8 8 8", "Fix fluid: viscosity must be finite and > 0"),
    ("fix u all fluid/flow water grid 8 8 8\nrun 0", "Fix fluid/flow: fluid fix 'water' does not exist"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix u all fluid/flow f grid 8 8 8\nrun 0",
     "Fix fluid/flow: no fix fluid/drag takes its drag from fluid 'f'"),
    ("fix f all fluid density 1000 bingham 1 0.1\nfix d all fluid/drag f law bingham\nfix u all fluid/flow f grid 8 8 8\nrun 0",
     "Fix fluid/flow: fluid 'f' is a Bingham fluid"),
]


@check
def bad_input(np_ranks: int):
    from concurrent.futures import ThreadPoolExecutor

    def verdict(k: int) -> str | None:
        lines, messages = BAD_INPUT[k]
        folder = Path(tmp) / f"bad{k}"
        folder.mkdir()
        deck = folder / "deck.lmp"
        deck.write_text("units si\natom_style sphere\nregion box block 0 1 0 1 0 1\ncreate_box 1 box\n"
                        "fix grav all gravity 9.81 vector 0 0 -1\n" + lines + "\n")
        out = run_deck(deck, {}, np_ranks, expect_failure=True, cwd=folder)
        messages = (messages,) if isinstance(messages, str) else messages
        if "ERROR" not in out.text or not any(m in out.text for m in messages):
            return f"{lines!r}: expected {' or '.join(messages)}; got {out.error}"
        return None

    with tempfile.TemporaryDirectory() as tmp:
        # Four decks at a time: a failing deck's run is mostly MPI's start-up and shutdown, waiting
        # (74 decks on 2 ranks: 127 s one at a time, 64 s two, 35 s four; user + system time 13 s).
        with ThreadPoolExecutor(max_workers=4) as pool:
            wrong = [w for w in pool.map(verdict, range(len(BAD_INPUT))) if w]
        assert not wrong, "\n".join(wrong)
        for units in ("metal", "real"):
            deck = Path(tmp) / "units.lmp"
            deck.write_text(f"units {units}\natom_style sphere\nregion box block 0 1 0 1 0 1\ncreate_box 1 box\n"
                            "fix f all fluid density 1 viscosity 1\nrun 0\n")
            out = run_deck(deck, {}, np_ranks, expect_failure=True, cwd=Path(tmp))
            assert f"requires coherent units (si, cgs, micro, nano or lj), not '{units}'" in out.text
        deck = Path(tmp) / "atomic.lmp"
        deck.write_text("units si\natom_style atomic\nregion box block 0 1 0 1 0 1\ncreate_box 1 box\n"
                        "fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f law stokes\n")
        out = run_deck(deck, {}, np_ranks, expect_failure=True, cwd=Path(tmp))
        assert "requires atom attributes radius and rmass" in out.text
    report(f"bad input: {len(BAD_INPUT) + 3} malformed decks each stopped with the expected error message")


@check(ranks=(1,))
def fuzz_input(np_ranks: int):
    """Every malformed command of tests/decks/fuzz.py ends with a LAMMPS error; valid ones run."""
    import subprocess
    from concurrent.futures import ThreadPoolExecutor

    import fuzz

    def outcome(case_and_dir):
        case, folder = case_and_dir
        deck = folder / "deck.lmp"
        deck.write_text(case.deck)
        try:
            out = run_batch(deck, {}, np_ranks, cwd=folder, timeout=60, check=False)
        except subprocess.TimeoutExpired:
            return case, "hang"
        refused = out.returncode != 0 and out.error is not None and out.error.startswith("ERROR")
        ran = out.returncode == 0 and out.error is None and "Loop time" in out.text
        if refused:
            return case, "refused" if not case.valid else "valid input refused: " + out.error
        if ran:
            return case, "ran" if case.valid else "silently accepted"
        return case, f"crash (exit {out.returncode})"

    cases = fuzz.cases()
    with tempfile.TemporaryDirectory() as tmp:
        folders = [Path(tmp) / f"case{k}" for k in range(len(cases))]
        for folder in folders:
            folder.mkdir()
        # Four at a time: like bad_input's, these runs mostly wait on start-up and shutdown.
        with ThreadPoolExecutor(max_workers=4) as pool:
            results = list(pool.map(outcome, zip(cases, folders)))
    bad = [(case, result) for case, result in results if result not in ("refused", "ran")]
    for case, result in bad:
        report(f"  {result}: {case.style}: {case.what}")
    refused = sum(result == "refused" for _, result in results)
    report(f"fuzz: {len(cases)} generated decks over {len(fuzz.STYLES)} command forms: {refused} malformed ones "
           f"refused with a LAMMPS error, {len(cases) - refused - len(bad)} valid ones ran, {len(bad)} wrong")
    assert not bad


# ---- the plugin route (an lmp built with the PLUGIN package) -----------------------------------------------
PLUGIN_STYLES = {("fix", "fluid"), ("fix", "fluid/buoyancy"), ("fix", "fluid/drag"), ("fix", "fluid/flow"),
                 ("fix", "nve/sphere/fluid"),
                 ("fix", "layers/hdf5"), ("compute", "concentration/grid"), ("compute", "contact/overlap"),
                 ("pair", "lubricate/fluid")}


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
