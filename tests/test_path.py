"""Reference paths: closed-form geometry of arcs and lane changes, waypoints, the default route."""

import numpy as np
import pytest

from robustctl.models.path import Curve, LaneChange, ReferencePath, Straight, default_route

V = 16.6667


def test_straight():
    p = ReferencePath.straight(10.0)
    assert p.T == 100 and p.duration == pytest.approx(10.0)
    np.testing.assert_array_equal(p.kappa, 0.0)
    np.testing.assert_allclose(p.X, V * p.t, rtol=1e-12)
    np.testing.assert_allclose(p.Y, 0.0, atol=1e-12)


def test_circular_arc_closed_form():
    """A constant-curvature path from the origin heading along X: X = R sin(s/R), Y = R (1 - cos(s/R))."""
    R = 150.0
    p = ReferencePath.from_curvature(lambda s: np.full_like(s, 1 / R), duration=20.0)
    s = p.s
    np.testing.assert_allclose(p.X, R * np.sin(s / R), atol=1e-3)
    np.testing.assert_allclose(p.Y, R * (1 - np.cos(s / R)), atol=1e-3)
    np.testing.assert_allclose(p.heading, s / R, atol=1e-12)
    np.testing.assert_allclose(p.kappa, 1 / R, rtol=1e-12)


def test_curve_turns_by_its_angle():
    c = Curve(300.0, -60.0, 70.0)
    assert c.length == pytest.approx(np.radians(60) * 300 + 70)
    p = ReferencePath.from_segments([c, Straight(100.0)])
    assert p.heading[-1] == pytest.approx(-np.radians(60), abs=1e-9)
    assert np.min(p.kappa) == pytest.approx(-1 / 300, rel=1e-9)
    assert np.max(p.kappa) <= 1e-15
    # clothoid: curvature ramps linearly at the entry
    sel = (p.s > 5) & (p.s < 65)
    mid = p.s[sel] + V * 0.1 / 2                                  # kappa[k] is the mean over the sample
    np.testing.assert_allclose(p.kappa[sel] / mid, -1 / 300 / 70, rtol=1e-9)


def test_lane_change_offset_and_heading():
    p = ReferencePath.from_segments([Straight(50.0), LaneChange(3.5, 150.0), Straight(100.0)])
    assert p.heading[-1] == pytest.approx(0.0, abs=1e-9)
    assert p.Y[-1] == pytest.approx(3.5, rel=1e-3)                # small-angle form, error ~ (2*3.5/150)^2
    assert np.max(np.abs(p.heading)) == pytest.approx(2 * 3.5 / 150, rel=1e-2)


def test_mean_curvature_turns_heading_exactly():
    p = default_route()
    np.testing.assert_allclose(np.diff(p.heading), p.kappa[:-1] * V * 0.1, atol=1e-12)


def test_default_route_is_realistic():
    p = default_route()
    assert p.duration >= 500.0
    assert p.speed == V and p.dt == 0.1
    kmax = np.max(np.abs(p.kappa))
    assert 1 / kmax >= 199.0                                    # radius >= 200 m
    assert V**2 * kmax <= 1.5                                   # lateral acceleration <= 1.5 m/s^2
    # curvature is continuous (clothoids, smooth lane changes): per-sample steps are far below
    # the 1/200 = 5e-3 1/m jump of an arc entered without a transition
    assert np.max(np.abs(np.diff(p.kappa))) < 2e-4
    assert np.any(p.kappa > 0) and np.any(p.kappa < 0)          # bends both ways
    assert p.kappa[0] == 0.0                                    # starts on a straight
    assert "default route" in repr(p)


def test_from_curvature_array_equals_callable_when_piecewise_constant():
    k = np.repeat([0.0, 1 / 300, -1 / 400, 0.0], 50)
    pa = ReferencePath.from_curvature(k)
    pc = ReferencePath.from_curvature(lambda s: k[np.minimum((s / (V * 0.1) - 1e-9).astype(int), k.size - 1)],
                                      duration=20.0)
    np.testing.assert_allclose(pa.kappa, k, rtol=1e-12)
    np.testing.assert_allclose(pa.X, pc.X, atol=0.05)
    np.testing.assert_allclose(pa.Y, pc.Y, atol=0.05)


def test_from_waypoints_circle():
    R = 250.0
    th = np.linspace(0, np.pi / 2, 40)
    p = ReferencePath.from_waypoints(R * np.sin(th), R * (1 - np.cos(th)))
    assert p.duration == pytest.approx(R * np.pi / 2 / V, abs=0.2)
    inner = p.kappa[10:-10]
    np.testing.assert_allclose(inner, 1 / R, rtol=2e-3)
    np.testing.assert_allclose(np.hypot(p.X, p.Y - R), R, atol=0.05)


def test_truncated():
    p = default_route()
    q = p.truncated(30.0)
    assert q.T == 300
    np.testing.assert_array_equal(q.kappa, p.kappa[:300])


@pytest.mark.parametrize("duration", [0.0, 0.05, -1.0, np.nan])
def test_path_shorter_than_one_step(duration):
    with pytest.raises(ValueError, match="one sample step"):
        ReferencePath.straight(duration)


def test_bad_inputs():
    with pytest.raises(ValueError, match="at least one sample"):
        ReferencePath.from_curvature([])
    with pytest.raises(ValueError, match="duration is required"):
        ReferencePath.from_curvature(lambda s: 0 * s)
    with pytest.raises(ValueError, match="kappa"):
        ReferencePath.from_curvature([0.0, np.nan])
    with pytest.raises(ValueError, match="speed"):
        ReferencePath.straight(10.0, speed=-1.0)
    with pytest.raises(ValueError, match="transition"):
        Curve(100.0, 10.0, 60.0)
    with pytest.raises(ValueError, match="radius"):
        Curve(0.0, 10.0)
    with pytest.raises(TypeError, match="segments"):
        ReferencePath.from_segments([Straight(10.0), "curve"])
    with pytest.raises(ValueError, match="waypoints"):
        ReferencePath.from_waypoints([0, 1, 2], [0, 0, 0])
    with pytest.raises(ValueError, match="Y"):
        ReferencePath.from_waypoints([0, 1, 2, 3], [0, 0, 0])
