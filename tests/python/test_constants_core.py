# SPDX-License-Identifier: GPL-2.0-or-later
"""constants.py's drag-law names and Boltzmann's constant are the core's: the core keeps one list of
drag laws (core/include/sediment/drag.hpp) and the constant (core/include/sediment/water.hpp)."""
from sediment import _core, constants


def test_the_drag_law_names_are_the_cores_list():
    laws = _core.drag_laws()
    assert list(constants.DRAG_LAWS) == [law["name"] for law in laws] == _core.drag_law_names()
    assert set(constants.BINGHAM_LAWS) == {law["name"] for law in laws if law["bingham_fluid"]}
    assert set(constants.DRAGS) == {law["name"] for law in laws if not law["bingham_fluid"]}
    assert set(constants.HINDRANCES) == set(_core.hindrance_names())


def test_the_hindrances_each_law_takes_come_from_the_list():
    takes = {law["name"]: law["hindrances"] for law in _core.drag_laws()}
    assert takes["standard"] == ["none", "difelice", "richardson-zaki", "garside"]
    assert takes["schiller-naumann"] == ["none", "difelice"]
    assert takes["difelice"] == ["none", "difelice"]
    assert takes["bingham"] == takes["zhang-li"] == ["none"]


def test_boltzmann_is_the_cores():
    assert constants.BOLTZMANN == _core.BOLTZMANN
    from sediment.constants import BOLTZMANN
    assert BOLTZMANN is _core.BOLTZMANN
