"""The haze Python module: scenes from dicts, numpy in and out, solutions, progress, errors."""
import numpy as np
import pytest

import haze


def emitting_box(width=8, height=6):
    # Seen straight down -z through a 2-degree field of view: every ray crosses the box's 1.2 depth
    # (to within 2e-4 relative).
    return {
        "camera": {"position": [0, 0, 4.0], "look_at": [0, 0, 0], "fov_y_deg": 2,
                   "width_px": width, "height_px": height},
        "medium": {"bounds": [[-1, -0.8, -0.6], [1, 0.8, 0.6]], "density": {"type": "constant"},
                   "sigma_t": [1.0, 2.0, 0.5], "albedo": 0.0,
                   "emission": {"strength": 2.0, "color": [1.0, 0.5, 0.25]}},
    }


def fog(density=None):
    scene = {
        "camera": {"position": [0, 0, 3.5], "look_at": [0, 0, 0], "width_px": 12, "height_px": 10},
        "medium": {"bounds": [[-1, -1, -1], [1, 1, 1]], "density": {"type": "constant", "value": 1.0},
                   "sigma_t": 1.5, "albedo": 0.9},
        "lights": [{"type": "point", "position": [0.2, 1.5, 0.3], "intensity": 5}],
    }
    return haze.Scene.from_dict(scene)


def test_render_matches_the_emitting_box_closed_form():
    # Along each ray through a uniformly emitting, non-scattering box L = L_e (1 - e^-tau) / sigma_t.
    result = haze.render(haze.Scene.from_dict(emitting_box()), "quadrature")
    image = result["radiance"]
    assert image.shape == (6, 8, 3) and image.dtype == np.float32
    sigma = np.array([1.0, 2.0, 0.5])
    expected = 2.0 * np.array([1.0, 0.5, 0.25]) * (1 - np.exp(-sigma * 1.2)) / sigma
    np.testing.assert_allclose(image, np.broadcast_to(expected, image.shape), rtol=1e-3)
    assert result["stats"]["seconds"] >= 0


def test_errors_carry_field_value_and_expected():
    bad = emitting_box()
    bad["medium"]["albedo"] = 1.5
    with pytest.raises(haze.Error) as e:
        haze.Scene.from_dict(bad)
    assert e.value.field == "medium.albedo"
    assert "1.5" in e.value.value
    assert "[0, 1]" in e.value.expected
    assert isinstance(e.value, ValueError)
    with pytest.raises(haze.Error, match="method"):
        haze.render(haze.Scene.from_dict(emitting_box()), "no_such_method")


def test_numpy_density_is_viewed_in_place():
    scene = fog()
    density = np.ones((8, 8, 8), dtype=np.float32)
    scene.set_density(density)
    before = haze.render(scene, "propagation", {"resolution": 8})["radiance"].mean()
    density[:] = 0.25  # the scene views the array: a new solution sees the change
    after = haze.render(scene, "propagation", {"resolution": 8})["radiance"]
    fresh = fog()
    fresh.set_density(np.full((8, 8, 8), 0.25, dtype=np.float32))
    np.testing.assert_array_equal(after, haze.render(fresh, "propagation", {"resolution": 8})["radiance"])
    assert abs(after.mean() - before) > 0.05 * before
    # Other layouts are copied, and a bad shape is refused by name.
    scene.set_density(np.ones((8, 8, 8), dtype=np.float64)[:, :, ::-1])
    with pytest.raises(haze.Error) as e:
        scene.set_density(np.ones((8, 8), dtype=np.float32))
    assert e.value.field == "density"
    with pytest.raises(haze.Error) as e:
        scene.set_density(np.full((4, 4, 4), -1.0, dtype=np.float32))
    assert e.value.field.startswith("medium.density")


def test_solution_renders_updates_and_reports_fields():
    scene = fog()
    density = np.ones((16, 16, 16), dtype=np.float32)
    scene.set_density(density)
    solution = haze.prepare(scene, "dom", {"resolution": 16, "directions": 32, "terms": 9})
    first = solution.render()["radiance"]
    thinner = np.full((16, 16, 16), 0.5, dtype=np.float32)
    report = solution.update(density=thinner)
    assert not report["rebuilt"] and report["redone"]
    second = solution.render()["radiance"]
    assert not np.allclose(first, second)
    fluence = solution.fluence(np.array([[0.0, 0.0, 0.0], [0.2, 1.0, 0.3]]))
    assert fluence.shape == (2, 3) and np.all(np.isfinite(fluence))
    assert fluence[1, 0] > fluence[0, 0]  # nearer the light


def test_progress_is_reported_and_can_cancel():
    scene = fog()
    fractions = []
    haze.render(scene, "reference", {"spp": 16}, progress=lambda f: fractions.append(f))
    assert fractions and fractions[-1] == pytest.approx(1.0) and fractions == sorted(fractions)
    with pytest.raises(haze.Cancelled):
        haze.render(scene, "reference", {"spp": 4096}, progress=lambda f: False)
    assert "dom" in haze.methods() and "reference" in haze.methods()


def particle_ball(count, seed=3):
    rng = np.random.default_rng(seed)
    points = rng.uniform(-1, 1, size=(4 * count, 3))
    return points[np.einsum("ij,ij->i", points, points) < 1][:count].astype(np.float32)


def test_particles_from_numpy_render_and_update():
    # A particles block with no positions yet, filled from numpy: the same image as the block
    # written out in the dict; moved particles through update() give the image of a new solution.
    positions = particle_ball(300)
    scene = {
        "camera": {"position": [0, 0.4, 4.0], "look_at": [0, 0, 0], "fov_y_deg": 38, "width_px": 16, "height_px": 12},
        "particles": {"positions": [], "sigma_t": 4.0, "albedo": 0.9},
        "lights": [{"type": "directional", "direction": [-0.5, -0.7, -0.5], "irradiance": 1.0}],
    }
    from_numpy = haze.Scene.from_dict(scene)
    from_numpy.set_particles(positions)
    scene["particles"]["positions"] = positions.tolist()
    in_dict = haze.Scene.from_dict(scene)
    a = haze.render(from_numpy, "network", {"directions": 32})["radiance"]
    b = haze.render(in_dict, "network", {"directions": 32})["radiance"]
    assert a.mean() > 0.01
    np.testing.assert_allclose(a, b, rtol=1e-6, atol=1e-7)

    moved = positions.copy()
    moved[:20] += np.float32(0.05)
    solution = haze.prepare(from_numpy, "network", {"directions": 32})
    report = solution.update(positions=moved)
    assert not report["rebuilt"]
    from_numpy.set_particles(moved)
    fresh = haze.render(from_numpy, "network", {"directions": 32})["radiance"]
    np.testing.assert_allclose(solution.render()["radiance"], fresh, rtol=2e-3, atol=1e-5)

    with pytest.raises(haze.Error) as e:
        from_numpy.set_particles(positions[:, :2])
    assert e.value.field == "particles.positions" and "(n, 3)" in e.value.expected
    bad = positions.copy()
    bad[7, 1] = np.nan
    with pytest.raises(haze.Error, match=r"particles.positions\[7\]"):
        from_numpy.set_particles(bad)
    with pytest.raises(haze.Error, match=r"particles.density"):
        from_numpy.set_particles(positions, density=np.ones(5, dtype=np.float32))
    with pytest.raises(haze.Error) as e:
        fog().set_particles(positions)
    assert e.value.field == "particles"
