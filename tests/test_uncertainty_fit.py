"""NormBounded.from_plants (a norm-bounded model covering a plant set) and sample_plants (scenario sets).

Containment is checked independently of the fit: for each plant the
least-squares ``Delta_i = pinv(H) D_i pinv(E)`` (numpy's pseudo-inverse) must
reproduce the deviation ``D_i = [F_i - F, G_i - G]`` and be a contraction.
"""

import numpy as np
import pytest

import robustctl as rc


def _deltas(unc, nominal, plants):
    """(Delta_i, residual_i) by least squares with numpy's pseudo-inverses."""
    E = np.hstack([unc.EF, unc.EG])
    Hp, Ep = np.linalg.pinv(unc.H), np.linalg.pinv(E)
    out = []
    for p in plants:
        D = np.hstack([p.F - nominal.F, p.G - nominal.G])
        Delta = Hp @ D @ Ep
        out.append((Delta, np.linalg.norm(D - unc.H @ Delta @ E, 2)))
    return out


def _random_plant(rng, n, m, dt=0.1):
    return rc.Plant(rng.normal(size=(n, n)) * 0.3, rng.normal(size=(n, m)), dt)


@pytest.mark.parametrize("n, m, N", [(2, 1, 3), (4, 2, 6), (3, 1, 1)])
def test_contains_every_plant(n, m, N):
    rng = np.random.default_rng(n * 10 + N)
    nominal = _random_plant(rng, n, m)
    plants = [rc.Plant(nominal.F + 0.05 * rng.normal(size=(n, n)), nominal.G + 0.05 * rng.normal(size=(n, m)), 0.1)
              for _ in range(N)]
    unc = rc.NormBounded.from_plants(nominal, plants)
    assert (unc.n, unc.m) == (n, m)
    norms = []
    for Delta, resid in _deltas(unc, nominal, plants):
        assert resid <= 1e-10
        norms.append(np.linalg.norm(Delta, 2))
    assert max(norms) <= 1 + 1e-10
    assert max(norms) == pytest.approx(1.0, abs=1e-10)       # the most deviating plant is on the boundary
    # perturb() with that Delta gives the plant back
    Delta0 = _deltas(unc, nominal, plants[:1])[0][0]
    back = unc.perturb(nominal, Delta0 / max(1.0, np.linalg.norm(Delta0, 2)))
    np.testing.assert_allclose(back.F, plants[0].F, atol=1e-10)
    np.testing.assert_allclose(back.G, plants[0].G, atol=1e-10)


def test_one_parameter_family_is_tight():
    rng = np.random.default_rng(3)
    n, m = 3, 1
    F0, G0 = rng.normal(size=(n, n)) * 0.3, rng.normal(size=(n, m))
    F1, G1 = np.outer(rng.normal(size=n), rng.normal(size=n)), rng.normal(size=(n, m))

    def plant(theta):
        return rc.Plant(F0 + theta * F1, G0 + theta * G1, 0.05)

    nominal = plant(0.0)
    thetas = (-1.0, 1.0, 0.3, -0.6)
    plants = [plant(t) for t in thetas]
    unc = rc.NormBounded.from_plants(nominal, plants)
    # the deviations theta [F1 G1] span the column and row spaces of [F1 G1]
    r = np.linalg.matrix_rank(np.hstack([F1, G1]))
    assert (unc.p, unc.l) == (r, r) == (2, 2)
    norms = [np.linalg.norm(D, 2) for D, _ in _deltas(unc, nominal, plants)]
    np.testing.assert_allclose(norms, np.abs(thetas), atol=1e-12)    # both extremes at ||Delta|| = 1
    # fitted on the two extremes alone, the model contains every plant in between
    ends = rc.NormBounded.from_plants(nominal, plants[:2])
    for Delta, resid in _deltas(ends, nominal, [plant(t) for t in np.linspace(-1, 1, 7)]):
        assert resid <= 1e-10 and np.linalg.norm(Delta, 2) <= 1 + 1e-12


def test_rank_cap_that_cannot_represent_raises():
    rng = np.random.default_rng(0)
    nominal = _random_plant(rng, 3, 2)
    plants = [rc.Plant(nominal.F + 0.1 * rng.normal(size=(3, 3)), nominal.G, 0.1) for _ in range(3)]
    with pytest.raises(ValueError, match=r"plants\[\d\] only to a relative error"):
        rc.NormBounded.from_plants(nominal, plants, rank=1)
    # a rank-1 family fits with rank=1
    d = np.outer([1.0, 0.0, 2.0], [0.5, -1.0, 0.0, 0.2, 0.1])
    fam = [rc.Plant(nominal.F + s * d[:, :3], nominal.G + s * d[:, 3:], 0.1) for s in (0.1, -0.2)]
    unc = rc.NormBounded.from_plants(nominal, fam, rank=1)
    assert (unc.p, unc.l) == (1, 1)


def test_from_plants_bad_input():
    rng = np.random.default_rng(1)
    nominal = _random_plant(rng, 2, 1)
    other = _random_plant(rng, 3, 1)
    with pytest.raises(ValueError, match=r"plants\[1\] must have n=2"):
        rc.NormBounded.from_plants(nominal, [nominal, other])
    with pytest.raises(ValueError, match=r"plants\[0\] must have the sampling time"):
        rc.NormBounded.from_plants(nominal, [rc.Plant(nominal.F, nominal.G, 0.2)])
    with pytest.raises(TypeError, match="plants must be a non-empty list"):
        rc.NormBounded.from_plants(nominal, [])
    with pytest.raises(TypeError, match="plants must be a non-empty list"):
        rc.NormBounded.from_plants(nominal, nominal)
    with pytest.raises(TypeError, match=r"plants\[0\] must be a robustctl.Plant"):
        rc.NormBounded.from_plants(nominal, [np.eye(2)])
    with pytest.raises(TypeError, match=r"nominal must be a robustctl\.Plant"):
        rc.NormBounded.from_plants(np.eye(2), [nominal])
    with pytest.raises(ValueError, match="do not deviate from nominal"):
        rc.NormBounded.from_plants(nominal, [nominal, rc.Plant(nominal.F, nominal.G, nominal.dt)])
    with pytest.raises(ValueError, match="tol must be"):
        rc.NormBounded.from_plants(nominal, [_random_plant(rng, 2, 1)], tol=2.0)
    with pytest.raises(TypeError, match="rank must be"):
        rc.NormBounded.from_plants(nominal, [_random_plant(rng, 2, 1)], rank=1.5)


# ---------------------------------------------------------------- sample_plants
def _spring_mass(mass, stiffness=1.0):
    return rc.Plant.from_continuous([[0.0, 1.0], [-stiffness / mass, 0.0]], [[0.0], [1.0 / mass]], dt=0.1)


def test_sample_plants_grid():
    s = rc.sample_plants(_spring_mass, {"mass": (1.0, 2.0), "stiffness": (0.5, 1.5)}, n=3)
    assert len(s) == 9 and s.names == ("mass", "stiffness")
    expected = [(a, b) for a in (1.0, 1.5, 2.0) for b in (0.5, 1.0, 1.5)]
    np.testing.assert_allclose(s.params, expected)
    for plant, (a, b) in zip(s, expected, strict=True):
        ref = _spring_mass(a, b)
        np.testing.assert_array_equal(plant.F, ref.F)
    assert s.as_dicts()[1] == {"mass": 1.0, "stiffness": 1.0}
    assert isinstance(s[0], rc.Plant) and len(list(s)) == 9
    assert "PlantSamples(N=9" in repr(s)


def test_sample_plants_lhs_strata_and_seed():
    a = rc.sample_plants(_spring_mass, {"mass": (1.0, 3.0), "stiffness": (0.0, 1.0)}, n=8, method="lhs", seed=4)
    b = rc.sample_plants(_spring_mass, {"mass": (1.0, 3.0), "stiffness": (0.0, 1.0)}, n=8, method="lhs", seed=4)
    np.testing.assert_array_equal(a.params, b.params)
    # one sample in each of the 8 strata of each parameter (Latin hypercube)
    strata_mass = np.floor((a.params[:, 0] - 1.0) / 2.0 * 8).astype(int)
    strata_k = np.floor(a.params[:, 1] * 8).astype(int)
    assert sorted(strata_mass) == list(range(8)) and sorted(strata_k) == list(range(8))


def test_sample_plants_then_from_plants():
    s = rc.sample_plants(_spring_mass, {"mass": (1.0, 2.0)}, n=5)
    nominal = _spring_mass(1.5)
    unc = rc.NormBounded.from_plants(nominal, list(s))
    for Delta, resid in _deltas(unc, nominal, s):
        assert resid <= 1e-10 and np.linalg.norm(Delta, 2) <= 1 + 1e-12


def test_sample_plants_bad_input():
    with pytest.raises(ValueError, match=r"ranges\['mass'\] must have low <= high"):
        rc.sample_plants(_spring_mass, {"mass": (2.0, 1.0)})
    with pytest.raises(ValueError, match=r"ranges\['mass'\] must be two finite numbers"):
        rc.sample_plants(_spring_mass, {"mass": (1.0, 2.0, 3.0)})
    with pytest.raises(TypeError, match="ranges must be a non-empty mapping"):
        rc.sample_plants(_spring_mass, [(1.0, 2.0)])
    with pytest.raises(TypeError, match="model must be a callable"):
        rc.sample_plants(None, {"mass": (1.0, 2.0)})
    with pytest.raises(TypeError, match=r"model must return a robustctl.Plant, model\(mass=1\) returned"):
        rc.sample_plants(lambda mass: np.eye(2), {"mass": (1.0, 2.0)})
    with pytest.raises(ValueError, match="one size and sampling time"):
        rc.sample_plants(lambda mass: rc.Plant(np.eye(2), [[0.0], [1.0]], dt=mass), {"mass": (1.0, 2.0)})
    with pytest.raises(ValueError, match="method must be one of"):
        rc.sample_plants(_spring_mass, {"mass": (1.0, 2.0)}, method="sobol")
    with pytest.raises(TypeError, match="n must be"):
        rc.sample_plants(_spring_mass, {"mass": (1.0, 2.0)}, n=2.0)
