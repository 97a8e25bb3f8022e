# SPDX-License-Identifier: GPL-2.0-or-later
"""Where a scene's grains start: stratified random placement, each size class uniform at every scale
above its spacing, and, with contacts, no two grains overlapping."""
from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:    # the scene calls `place` as it is planned
    from .scene import Scene


def place(scene: Scene) -> None:
    """Stratified random placement: each class's particles get distinct cells of a grid of about
    cubic cells (as many as the particles) over the sub-volume, one at a random point of each, so
    every class starts uniform at every scale above its spacing. Centres stay one radius inside the
    column. With contacts, overlapping grains are redrawn (see _separate). Under two-way coupling each
    particle is placed independently: the flow is driven by the fluctuations of the grains' density,
    which stratified cells would take away (their counts' dispersion is a third of the grains')."""
    rng = np.random.default_rng(scene.seed)
    lateral = 1 if scene.geometry == "slab" else 2
    diameters, weights, positions = [], [], []
    for d, n, w in zip(scene.classes.diameter, scene.classes.count, scene.classes.weight):
        if n == 0:
            continue
        if scene.effects.flow:
            cells = rng.random((int(n), 3)) * [scene.width, scene.width, scene.height - d]
        else:
            cells = _stratify(rng, int(n), scene.width, scene.height - d, lateral)
        lo = np.array([0.0, 0.0, 0.5 * d])
        positions.append(lo + cells)
        diameters.append(np.full(n, d))
        weights.append(np.full(n, w))
    scene.diameter = np.concatenate(diameters)
    scene.weight = np.concatenate(weights)
    scene.position = np.concatenate(positions)
    if scene.geometry == "slab":                       # (x, 0, height) -> (x, height, 0) in LAMMPS 2d
        scene.position = scene.position[:, [0, 2, 1]]
    if scene.effects.interacting:
        _separate(scene, rng)


def _stratify(rng: np.random.Generator, n: int, width: float, height: float, lateral: int) -> np.ndarray:
    """n points, one in each of n distinct cells of a grid over [0, width]^lateral x [0, height]."""
    side = (width ** lateral * height / n) ** (1 / (lateral + 1))
    across = max(1, round(width / side))
    rows = math.ceil(n / across ** lateral)
    chosen = rng.choice(across ** lateral * rows, size=n, replace=False)
    index = [chosen % across, (chosen // across) % across if lateral == 2 else np.zeros(n, int),
             chosen // across ** lateral]
    sizes = [width / across, width / across if lateral == 2 else 0.0, height / rows]
    return np.column_stack([(index[k] + rng.random(n)) * sizes[k] for k in range(3)])


def _separate(scene: Scene, rng: np.random.Generator, attempts: int = 200) -> None:
    """Redraws overlapping grains (the smaller of each pair) anywhere in the sub-volume until none overlap."""
    from scipy.spatial import cKDTree

    radius = 0.5 * scene.diameter
    vertical = 1 if scene.geometry == "slab" else 2
    periodic = [scene.width, scene.thickness, 4 * scene.height]     # vertical: never wraps
    if scene.geometry == "slab":
        periodic = [scene.width, 4 * scene.height, scene.thickness]
    for _ in range(attempts):
        points = scene.position.copy()
        points[:, vertical] += scene.height    # keep inside [0, boxsize)
        points[:, 0] %= scene.width
        if scene.geometry == "column":
            points[:, 1] %= scene.width
        tree = cKDTree(points, boxsize=periodic)
        pairs = tree.query_pairs(2 * radius.max(), output_type="ndarray")
        if len(pairs):
            gap = np.linalg.norm(_periodic_delta(points[pairs[:, 0]] - points[pairs[:, 1]], periodic), axis=1)
            pairs = pairs[gap < radius[pairs[:, 0]] + radius[pairs[:, 1]]]
        if not len(pairs):
            return
        move = np.unique(np.where(radius[pairs[:, 0]] <= radius[pairs[:, 1]], pairs[:, 0], pairs[:, 1]))
        scene.position[move, 0] = rng.random(len(move)) * scene.width
        if scene.geometry == "column":
            scene.position[move, 1] = rng.random(len(move)) * scene.width
        scene.position[move, vertical] = radius[move] + rng.random(len(move)) * (scene.height - 2 * radius[move])
    raise ValueError("could not place the grains without overlaps: the sub-volume is too crowded")


def _periodic_delta(delta: np.ndarray, box: list[float]) -> np.ndarray:
    box = np.asarray(box)
    return delta - box * np.rint(delta / box)
