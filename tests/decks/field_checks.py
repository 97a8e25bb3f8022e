# SPDX-License-Identifier: GPL-2.0-or-later
"""Deck tests of the concentration field and the layer files (compute concentration/grid, fix
layers/hdf5, restarts): registered with the others of checks.py (harness.check), run as
`python3 checks.py NAME [--np N]`."""
from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

import numpy as np

from harness import HERE, check, read_dump_frames, report, run_deck


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


# ---- concentration every N steps, and the dumps and profiles it is read from ------------------------
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
