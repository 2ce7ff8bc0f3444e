"""Resident memory of a simulation relit through Solution.update (issue 49's case): a propagation
solution of a 64^3 cloud updated `frames` times after WARM updates, each a new float32 density
(1 MiB). glibc raises its mmap threshold when the first large block is freed, so the heap settles
at its working set within the first updates; the growth is measured from there.
Usage: PYTHONPATH=build/test/python python3 bench/python_update_memory.py [frames] [method] [n]"""
import os
import sys

import numpy as np

import haze


def resident_mb():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20


frames = int(sys.argv[1]) if len(sys.argv) > 1 else 200
method = sys.argv[2] if len(sys.argv) > 2 else "propagation"
n = int(sys.argv[3]) if len(sys.argv) > 3 else 64
scene = haze.Scene.from_dict({
    "camera": {"position": [0.3, 0.4, 3.5], "look_at": [0, 0, 0], "width_px": 64, "height_px": 48},
    "medium": {"bounds": [[-1, -1, -1], [1, 1, 1]], "density": {"type": "constant"}, "sigma_t": 1.5, "albedo": 0.9},
    "lights": [{"type": "point", "position": [0.2, 1.5, 0.3], "intensity": 5}],
})
rng = np.random.default_rng(1)
scene.set_density(rng.random((n, n, n), dtype=np.float32))
solution = haze.prepare(scene, method, {"directions": 32, "terms": 9} if method == "dom" else {})
WARM = 10
after = []
for frame in range(WARM + frames):
    solution.update(density=rng.random((n, n, n), dtype=np.float32))
    after.append(resident_mb())
settled = max(after[:WARM])
print(f"{method} {n}^3: resident {after[0]:.1f} MB after the first update, at most {settled:.1f} MB over the first {WARM}; over the "
      f"{frames} updates after those at most {max(after[WARM:]) - settled:+.2f} MB, at the end {after[-1] - settled:+.2f} MB")
