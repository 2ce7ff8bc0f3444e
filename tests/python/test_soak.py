"""A simulation relit every frame (docs/PYTHON.md, "Arrays Haze views"): 1,000 updates and renders
of a dom and a propagation solution, each frame a new numpy density, keep resident memory flat, and
the last frame equals a fresh solution of the last density."""
import os

import numpy as np
import pytest

import haze

FRAMES = 1000
SETTLED = 100  # frames before memory is measured: allocators and caches warm
WINDOW = 10  # resident memory is the largest over this many frames (the heap breathes with each array)
GROWTH_LIMIT = 2 << 20  # bytes of resident memory the remaining 900 frames may add


def resident_bytes():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def puff(n, frame):
    # A Gaussian puff circling inside the unit box: a new (n, n, n) float32 array each frame, as a
    # simulation hands over (z, y, x order, x fastest).
    t = 2 * np.pi * frame / 200
    c = 0.35 * np.array([np.cos(t), np.sin(t), 0.5 * np.sin(2 * t)])
    x = (np.arange(n) + 0.5) / n * 2 - 1
    z, y, xx = np.meshgrid(x, x, x, indexing="ij")
    r2 = (xx - c[0]) ** 2 + (y - c[1]) ** 2 + (z - c[2]) ** 2
    return (0.2 + 2.0 * np.exp(-r2 / 0.15)).astype(np.float32)


def scene():
    return haze.Scene.from_dict({
        "camera": {"position": [0.3, 0.4, 3.5], "look_at": [0, 0, 0], "width_px": 12, "height_px": 10},
        "medium": {"bounds": [[-1, -1, -1], [1, 1, 1]], "density": {"type": "constant"},
                   "sigma_t": 1.5, "albedo": 0.9},
        "lights": [{"type": "point", "position": [0.2, 1.5, 0.3], "intensity": 5}],
    })


@pytest.mark.parametrize("method,n,settings,rtol", [
    # GMRES from the previous moments to the tolerance (1e-4) against a cold solve to it.
    ("dom", 16, {"directions": 32, "terms": 9}, 2e-3),
    # Injection and optical depths redone whole: the same arithmetic as a fresh solution.
    ("propagation", 32, {}, 1e-6),
])
def test_a_thousand_updates_keep_memory_flat(method, n, settings, rtol):
    s = scene()
    s.set_density(puff(n, 0))
    solution = haze.prepare(s, method, settings, threads=2)
    resident = []
    for frame in range(1, FRAMES + 1):
        density = puff(n, frame)
        solution.update(density=density, threads=2)
        image = solution.render(threads=2)["radiance"]
        del density  # the solution holds the array it views, and only that one
        resident.append(resident_bytes())
    growth = max(resident[-WINDOW:]) - max(resident[SETTLED - WINDOW:SETTLED])
    assert growth < GROWTH_LIMIT, f"{method}: resident memory grew {growth / 2**20:.2f} MB over {FRAMES - SETTLED} frames"

    fresh = scene()
    fresh.set_density(puff(n, FRAMES))
    expected = haze.prepare(fresh, method, settings, threads=2).render(threads=2)["radiance"]
    assert np.all(np.isfinite(image)) and image.mean() > 1e-3
    np.testing.assert_allclose(image, expected, rtol=rtol, atol=rtol * expected.max())


def test_replaced_arrays_are_released():
    # The scene and the solution each hold the one array they view; a replaced one is dropped.
    import sys
    first, second = puff(8, 0), puff(8, 1)
    base = sys.getrefcount(first)
    s = scene()
    s.set_density(first)
    assert sys.getrefcount(first) == base + 1
    solution = haze.prepare(s, "propagation", {"resolution": 8})
    assert sys.getrefcount(first) == base + 2
    solution.update(density=second)
    assert sys.getrefcount(first) == base + 1  # the scene still views it
    s.set_density(second)
    assert sys.getrefcount(first) == base
    copied = np.ones((8, 8, 8))  # float64: copied, so not held
    copied_base = sys.getrefcount(copied)
    solution.update(density=copied)
    assert sys.getrefcount(copied) == copied_base
