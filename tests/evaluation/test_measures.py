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


def _grid_cells(rng, nx, ny, missing):
    cells = np.array([(x, y) for x in range(nx) for y in range(ny)], dtype=float)
    cells = cells[rng.random(len(cells)) >= missing]
    return cells[rng.permutation(len(cells))]  # image order unrelated to the grid order


def test_nearest_cell_ties_go_to_the_lower_index():
    from bionav.evaluation.agent import nearest_cell_index

    cells = np.array([[3.0, 0.0], [1.0, 0.0], [2.0, 0.0], [2.0, 1.0]])
    # (1.5, 0) is half-way between cells 1 and 2; (2.5, 0) between 0 and 2; (2, 0.5) between 2 and 3
    got = nearest_cell_index(np.array([[1.5, 0.0], [2.5, 0.0], [2.0, 0.5], [2.6, 0.9], [-4.0, 0.2]]), cells)
    assert list(got) == [1, 0, 2, 3, 1]


@pytest.mark.parametrize("missing", [0.0, 0.2])
def test_compiled_agent_batch_equals_plain_trials(missing):
    """agent_success gives exactly run_agents' outcome for every trial: ideal-ish, noisy, random and
    axis-aligned fields (ties between cells), NaN directions, missing cells, agents leaving the grid."""
    from bionav.evaluation.agent import agent_success
    from bionav.evaluation.measures import ideal_home_angles

    rng = np.random.default_rng(3)
    nx, ny = 7, 9
    cells = _grid_cells(rng, nx, ny, missing)
    n = len(cells)
    ideal = np.nan_to_num(ideal_home_angles(cells, cells))
    fields = np.stack([
        ideal + rng.normal(0, 0.3, (n, n)),
        ideal + rng.normal(0, 1.5, (n, n)),
        rng.uniform(-np.pi, np.pi, (n, n)),
        rng.integers(-4, 4, (n, n)) * (np.pi / 2),
        np.where(rng.random((n, n)) < 0.2, np.nan, ideal + rng.normal(0, 0.8, (n, n))),
    ])  # fmt: skip
    fast = agent_success(fields, cells, cells, grid_shape=(nx, ny), step_length=0.5, success_radius=1.0)
    assert fast.shape == fields.shape
    for lv in range(len(fields)):
        for s in range(n):
            ref, _ = run_agents(fields[lv, s], cells, cells[s], cells, grid_shape=(nx, ny))
            np.testing.assert_array_equal(fast[lv, s], ref.success, err_msg=f"field {lv} snapshot {s}")
    assert 0.0 < fast.mean() < 1.0
    # snapshots that are not the current views' cells, other step and radius
    snaps = cells[:4] + 0.25
    fast = agent_success(fields[1, :4], cells, snaps, grid_shape=(nx, ny), step_length=0.3, success_radius=0.7)
    for s in range(4):
        ref, _ = run_agents(fields[1, s], cells, snaps[s], cells, grid_shape=(nx, ny), step_length=0.3,
                            success_radius=0.7)
        np.testing.assert_array_equal(fast[s], ref.success)


def test_agent_batch_off_the_lattice_uses_the_plain_trials():
    from bionav.evaluation.agent import agent_success

    rng = np.random.default_rng(5)
    cells = rng.uniform(0, 5, (12, 2))
    angles = rng.uniform(-np.pi, np.pi, (12, 12))
    fast = agent_success(angles, cells, cells, grid_shape=(5, 5))
    for s in range(12):
        np.testing.assert_array_equal(fast[s], run_agents(angles[s], cells, cells[s], cells, grid_shape=(5, 5))[0].success)
