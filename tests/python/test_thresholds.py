"""kdm.Tileset.thresholds: the count at which each point appears, as callers fade objects in with it.
Stable mode at a constant density emits exactly the points whose thresholds lie below its count."""
import numpy as np
import pytest

import kdm
from conftest import TINY_RECIPE

BUILTIN = kdm.Tileset.builtin()
RECT = (-1.5, 0.25, 2.5, 3.75)


def ids(result):
    """Each point's stable id (tile_x, tile_y, rank, depth), in the result's order."""
    return list(zip(result.tile[:, 0].tolist(), result.tile[:, 1].tolist(), result.rank.tolist(),
                    result.points["depth"].tolist()))


def test_the_points_a_rising_count_adds_have_thresholds_between_the_counts():
    before = BUILTIN.query(RECT, scale=300)
    after = BUILTIN.query(RECT, scale=330)
    t_before, t_after = BUILTIN.thresholds(before), BUILTIN.thresholds(after)
    assert t_before.shape == (len(before),) and t_before.dtype == np.float64
    assert (t_before >= 0).all() and (t_before < 300).all() and (t_after < 330).all()
    old = set(ids(before))
    added = np.array([k not in old for k in ids(after)])
    assert added.sum() == len(after) - len(before) > 100
    assert (t_after[added] >= 300).all()


def test_fade_weights_follow_the_documented_rule():
    # Weights over the last 10% of density: between 0 and 1, 1 for the points present at 1/1.1 of it.
    scale = 2000
    result = BUILTIN.query(RECT, scale=scale)
    weights = np.clip((scale / BUILTIN.thresholds(result) - 1) / 0.1, 0, 1)
    settled = set(ids(BUILTIN.query(RECT, scale=scale / 1.1)))
    full = np.array([k in settled for k in ids(result)])
    assert (weights[full] == 1).all() and (weights[~full] < 1).all() and (~full).sum() > 100


def test_bad_arguments_are_refused():
    with pytest.raises(TypeError, match="QueryResult"):
        BUILTIN.thresholds(np.zeros((3, 2)))
    tiny = kdm.bake(TINY_RECIPE)
    dense = BUILTIN.query((0, 0, 1, 1), scale=20000)  # ranks past the tiny set's tiles
    with pytest.raises(ValueError, match="not a point of this tile set"):
        tiny.thresholds(dense)
