"""Quality measures and the return agent against hand-computed cases (thesis 3.2)."""

import numpy as np
import pytest

from bionav.evaluation.agent import max_travel_length, run_agents
from bionav.evaluation.measures import AE_NO_DIRECTION, angular_errors, ideal_home_angles, quality_measures


def test_ideal_home_angles_hand_computed():
    s = np.array([[0, 0]])
    c = np.array([[1, 0], [0, 1], [1, 1], [0, 0], [-2, 0]])
    got = ideal_home_angles(s, c)[0]
    expected = [np.pi, -np.pi / 2, -3 * np.pi / 4, np.nan, 0.0]
    np.testing.assert_allclose(got[[0, 1, 2, 4]], np.array(expected)[[0, 1, 2, 4]])
    assert np.isnan(got[3])


def test_angular_error_wraps_and_scores_missing_direction():
    ideal = np.array([[np.pi - 0.1, 0.0, 1.0, np.nan]])
    home = np.array([[-np.pi + 0.1, 0.5, np.nan, 2.0]])
    ae = angular_errors(home, ideal)
    np.testing.assert_allclose(ae[0, :3], [0.2, 0.5, AE_NO_DIRECTION])
    assert np.isnan(ae[0, 3])


def test_quality_measures_hand_computed():
    # two snapshots, three cells; the diagonal does not count
    ae = np.array([[np.nan, 0.2, 0.4], [0.1, np.nan, 0.9]])
    success = np.array([[False, True, False], [True, False, True]])
    q = quality_measures(ae, success)
    np.testing.assert_allclose(q.aae_s, [0.3, 0.5])
    np.testing.assert_allclose(q.mae_s, [0.3, 0.5])
    np.testing.assert_allclose(q.rr_s, [0.5, 1.0])
    assert q.aae == pytest.approx(0.4)
    assert q.mae == pytest.approx(0.4)
    assert q.rr == pytest.approx(0.75)


def test_mae_star_is_median_of_medians_odd_count():
    ae = np.array([[np.nan, 0.1, 0.2, 0.9], [0.3, np.nan, 0.3, 0.3], [1.0, 2.0, np.nan, 3.0]])
    q = quality_measures(ae, np.ones_like(ae, dtype=bool))
    np.testing.assert_allclose(q.mae_s, [0.2, 0.3, 2.0])
    assert q.mae == pytest.approx(0.3)


def test_perfect_home_vectors_always_arrive():
    xs, ys = np.meshgrid(np.arange(5), np.arange(4), indexing="ij")
    pos = np.stack([xs.ravel(), ys.ravel()], axis=1)
    s = np.array([3, 1])
    angles = np.arctan2(s[1] - pos[:, 1], s[0] - pos[:, 0])
    result, _ = run_agents(angles, pos, s, pos, grid_shape=(5, 4))
    assert result.success.all()


def test_agent_that_never_arrives_gives_up_after_half_circumference():
    pos = np.array([[x, 0] for x in range(6)])
    s = np.array([0, 0])
    away = np.zeros(len(pos))  # everyone is told to go +x: away from the snapshot
    result, paths = run_agents(away, pos, s, pos[3:4], grid_shape=(6, 1), record_paths=True)
    assert not result.success[0]
    # half circumference (6-1)+(1-1) = 5 grid units at 0.5 per step -> 10 steps
    assert max_travel_length((6, 1)) == 5.0
    assert result.steps[0] == 10
    np.testing.assert_allclose(paths[0][-1], [8.0, 0.0], atol=1e-12)


def test_agent_uses_nearest_existing_cell_when_cells_are_missing():
    # cells (1,0) and (2,0) are missing; (3,0) says "go -x"
    pos = np.array([[0, 0], [3, 0]])
    s = np.array([0, 0])
    result, paths = run_agents(np.array([np.pi, np.pi]), pos, s, pos[1:], grid_shape=(4, 1), record_paths=True)
    # 3 -> 2.5 -> 2.0 -> 1.5 -> 1.0 -> 0.5 (< 1 from the snapshot): five steps
    assert result.success[0] and result.steps[0] == 5
    # if the snapshot cell gives no direction, the agent reaches x = 1.5, whose nearest
    # existing cell is a tie resolved to the lower index (the snapshot cell): it stops there
    result, paths = run_agents(np.array([np.nan, np.pi]), pos, s, pos[1:], grid_shape=(4, 1), record_paths=True)
    assert not result.success[0]
    np.testing.assert_allclose(paths[0][-1], [1.5, 0.0], atol=1e-12)
