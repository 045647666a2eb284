"""robustctl.InputMemoryFeedback (u[k] = K x[k] + K_input u[k-1]) and PathFollowing.run_laws."""

import numpy as np
import pytest

import robustctl as rc
from robustctl.models import truck
from robustctl.models.path import default_route
from robustctl.models.pathfollow import PathFollowing


def _law(seed=0, n=3, m=2):
    rng = np.random.default_rng(seed)
    plant = rc.Plant(rng.standard_normal((n, n)) / n, rng.standard_normal((n, m)), dt=0.1)
    return plant, rc.InputMemoryFeedback(rng.standard_normal((m, n)), rng.standard_normal((m, m)))


def test_closed_loop_is_the_block_matrix_and_drives_a_direct_recursion():
    plant, law = _law()
    F, G, K, Ku = plant.F, plant.G, law.K, law.K_input
    np.testing.assert_allclose(law.closed_loop(plant), np.block([[F + G @ K, G @ Ku], [K, Ku]]), rtol=1e-14)
    # u[k] = K x[k] + Ku u[k-1], u[-1] = 0, simulated directly and by powers of the closed loop
    x, u_prev = np.array([1.0, -0.5, 0.2]), np.zeros(2)
    xa = np.concatenate([x, u_prev])
    A = law.closed_loop(plant)
    for _ in range(5):
        u = law(x, u_prev)
        x, u_prev = F @ x + G @ u, u
        xa = A @ xa
        np.testing.assert_allclose(xa, np.concatenate([x, u_prev]), rtol=1e-12, atol=1e-14)
    assert law.gain.shape == (2, 5) and law.has_memory
    assert law.is_stabilizing(plant) == bool(np.max(np.abs(np.linalg.eigvals(A))) < 1 - 1e-9)


def test_static_law_is_the_plain_state_feedback():
    plant, law = _law()
    static = rc.InputMemoryFeedback(law.K)
    assert not static.has_memory and static.augmented_plant(plant) is plant
    np.testing.assert_array_equal(static.closed_loop(plant), plant.F + plant.G @ law.K)
    np.testing.assert_array_equal(static([1.0, 2.0, 3.0], [5.0, 5.0]), law.K @ [1.0, 2.0, 3.0])


def test_augmented_uncertainty_leaves_the_previous_input_exact():
    plant, law = _law()
    unc = rc.NormBounded(np.ones((3, 1)), [[0.1, 0.2, 0.3]], [[0.4, 0.5]])
    aug = law.augmented_uncertainty(unc, plant)
    np.testing.assert_array_equal(aug.H, [[1.0], [1.0], [1.0], [0.0], [0.0]])
    np.testing.assert_array_equal(aug.EF, [[0.1, 0.2, 0.3, 0.0, 0.0]])
    np.testing.assert_array_equal(aug.EG, unc.EG)


def test_bad_input():
    plant, law = _law()
    with pytest.raises(ValueError, match="K_input must have 2 rows"):
        rc.InputMemoryFeedback(law.K, np.eye(3))
    with pytest.raises(ValueError, match="plant must have n=4"):
        rc.InputMemoryFeedback(np.ones((2, 4)), np.eye(2)).closed_loop(plant)
    with pytest.raises(ValueError, match="discrete-time"):
        law.closed_loop(rc.Plant(plant.F, plant.G, dt=None))
    with pytest.raises(ValueError, match="x must have 3 entries"):
        law([1.0, 2.0])
    with pytest.raises(TypeError, match="InputMemoryFeedback"):
        PathFollowing(default_route(duration=1.0), [0.0]).run_laws([law.K])


def test_run_laws_keeps_the_order_of_a_mixed_list():
    """Static and memory laws in one call; a memory law with K_input = 0 is the static law (same loop)."""
    sim = PathFollowing(default_route(duration=5.0), [0.0, 300.0])
    plant = truck.truck_plant(0.0)
    K1 = rc.lqr(plant, Q=np.diag([1.0, 1.0, 10.0, 10.0]), R=[[1.0]]).K
    K2 = rc.lqr(plant).K
    laws = [rc.InputMemoryFeedback(K1, [[0.0]]), rc.InputMemoryFeedback(K2), rc.InputMemoryFeedback(K1, [[0.2]]),
            rc.InputMemoryFeedback(K1)]
    res = sim.run_laws(laws, backend="numpy")
    mse = res.mse()
    assert mse.shape == (4, 2, 4) and res.errors.shape[0] == 4
    np.testing.assert_allclose(mse[0], mse[3], rtol=1e-10)
    np.testing.assert_allclose(mse[1], sim.run(K2, backend="numpy").mse()[0], rtol=1e-12)
    np.testing.assert_allclose(mse[2], sim.run(K1, K_input=[[0.2]], backend="numpy").mse()[0], rtol=1e-12)
    assert not np.allclose(mse[2], mse[3])
