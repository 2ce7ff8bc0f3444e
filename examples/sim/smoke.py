"""A small smoke simulation relit every frame (docs/SIMULATIONS.md).

Stable fluids (Stam 1999) on an n^3 grid over [-1, 1]^3 with numpy: a hot source near the floor,
buoyancy, semi-Lagrangian advection, a Jacobi pressure projection. Every frame the DOM solution is
updated with the new density (warm: from the previous frame's moments) and rendered; with --cold
it is also prepared from scratch, for comparison. Writes frame_NNN.exr and .png, and smoke.gif
when Pillow is there; prints each frame's warm solve, render and cold solve times.

    PYTHONPATH=build/test/python /usr/bin/python3 examples/sim/smoke.py --size 48 --frames 24
"""
import argparse
import os
import time

import numpy as np

import haze


def trilinear(field, x, y, z):
    """field sampled at fractional cell coordinates (clamped to the grid), x fastest axis last."""
    n = field.shape[0]
    x, y, z = (np.clip(c, 0, n - 1.001) for c in (x, y, z))
    i, j, k = x.astype(int), y.astype(int), z.astype(int)
    fx, fy, fz = x - i, y - j, z - k
    out = 0.0
    for dk, wz in ((0, 1 - fz), (1, fz)):
        for dj, wy in ((0, 1 - fy), (1, fy)):
            for di, wx in ((0, 1 - fx), (1, fx)):
                out = out + wz * wy * wx * field[k + dk, j + dj, i + di]
    return out


def advect(field, u, v, w, dt):
    n = field.shape[0]
    k, j, i = np.meshgrid(np.arange(n), np.arange(n), np.arange(n), indexing="ij")
    return trilinear(field, i - dt * u, j - dt * v, k - dt * w)


def project(u, v, w, iterations=30):
    """Removes the velocity's divergence (Jacobi iterations on the pressure Poisson equation)."""
    div = np.zeros_like(u)
    div[1:-1, 1:-1, 1:-1] = 0.5 * (u[1:-1, 1:-1, 2:] - u[1:-1, 1:-1, :-2] + v[1:-1, 2:, 1:-1] - v[1:-1, :-2, 1:-1]
                                   + w[2:, 1:-1, 1:-1] - w[:-2, 1:-1, 1:-1])
    p = np.zeros_like(u)
    for _ in range(iterations):
        p[1:-1, 1:-1, 1:-1] = (p[1:-1, 1:-1, 2:] + p[1:-1, 1:-1, :-2] + p[1:-1, 2:, 1:-1] + p[1:-1, :-2, 1:-1]
                               + p[2:, 1:-1, 1:-1] + p[:-2, 1:-1, 1:-1] - div[1:-1, 1:-1, 1:-1]) / 6.0
    u[1:-1, 1:-1, 1:-1] -= 0.5 * (p[1:-1, 1:-1, 2:] - p[1:-1, 1:-1, :-2])
    v[1:-1, 1:-1, 1:-1] -= 0.5 * (p[1:-1, 2:, 1:-1] - p[1:-1, :-2, 1:-1])
    w[1:-1, 1:-1, 1:-1] -= 0.5 * (p[2:, 1:-1, 1:-1] - p[:-2, 1:-1, 1:-1])


class Smoke:
    def __init__(self, n):
        self.n = n
        self.density = np.zeros((n, n, n), dtype=np.float32)  # [z, y, x]
        self.u, self.v, self.w = (np.zeros((n, n, n)) for _ in range(3))
        c = (np.arange(n) + 0.5) / n * 2 - 1
        z, y, x = np.meshgrid(c, c, c, indexing="ij")
        self.source = np.exp(-((x + 0.2) ** 2 + (y + 0.75) ** 2 + z ** 2) / (2 * 0.12 ** 2))

    def step(self, dt=1.0):
        n = self.n
        self.density += 0.6 * self.source.astype(np.float32)
        self.v += dt * 0.04 * n / 32 * self.density  # buoyancy: up (+y) where smoke is
        self.u += dt * 0.01 * n / 32 * self.density  # and a drift in +x
        project(self.u, self.v, self.w)
        u, v, w = self.u.copy(), self.v.copy(), self.w.copy()
        self.u, self.v, self.w = (advect(f, u, v, w, dt) for f in (u, v, w))
        self.density = np.ascontiguousarray(0.995 * advect(self.density, u, v, w, dt), dtype=np.float32)


def scene_for(n, width, height):
    return haze.Scene.from_dict({
        "camera": {"position": [0.4, 0.3, 3.6], "look_at": [0, 0, 0], "fov_y_deg": 38, "width_px": width, "height_px": height},
        "medium": {"bounds": [[-1, -1, -1], [1, 1, 1]], "density": {"type": "constant"},
                   "sigma_t": 8.0, "albedo": 0.9, "phase": {"type": "hg", "g": 0.4}},
        "lights": [{"type": "directional", "direction": [0.4, -0.8, -0.45], "irradiance": 4.0},
                   {"type": "point", "position": [-1.4, 0.6, 1.2], "intensity": [3, 2.4, 1.8]}],
        "background": [0.02, 0.025, 0.035],
    })


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=48, help="cells per axis")
    parser.add_argument("--frames", type=int, default=24)
    parser.add_argument("--width", type=int, default=160)
    parser.add_argument("--height", type=int, default=120)
    parser.add_argument("--out", default="smoke_frames")
    parser.add_argument("--cold", action="store_true", help="also prepare every frame from scratch, to compare")
    parser.add_argument("--warm-iterations", type=int, default=1, help="DOM sweeps per update after the first-collision one (0: GMRES to the tolerance)")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)

    smoke = Smoke(args.size)
    for _ in range(12):  # let some smoke in before the first frame
        smoke.step()
    scene = scene_for(args.size, args.width, args.height)
    scene.set_density(smoke.density)
    # Warm: k sweeps from the previous frame's moments after the first-collision one, each corrected by
    # diffusion synthetic acceleration (docs/DOM.md, docs/SIMULATIONS.md).
    settings = {"resolution": args.size, "directions": 48, "terms": 9, "warm_iterations": args.warm_iterations}
    start = time.perf_counter()
    solution = haze.prepare(scene, "dom", settings)
    print(f"frame   0: cold prepare {time.perf_counter() - start:7.3f} s")
    print("frame  simulate  warm update  render  cold prepare  warm lag  redone")
    previews = []
    for frame in range(args.frames):
        t0 = time.perf_counter()
        smoke.step()
        t1 = time.perf_counter()
        report = solution.update(density=smoke.density)
        t2 = time.perf_counter()
        image = solution.render()["radiance"]
        t3 = time.perf_counter()
        cold = ""
        if args.cold:
            fresh = scene_for(args.size, args.width, args.height)
            fresh.set_density(smoke.density)
            c0 = time.perf_counter()
            cold_solution = haze.prepare(fresh, "dom", settings)
            c1 = time.perf_counter()
            # How far the warm image trails the cold one: relative RMS difference.
            cold_image = cold_solution.render()["radiance"]
            lag = np.sqrt(np.mean((image - cold_image) ** 2) / np.mean(cold_image ** 2))
            cold = f"{c1 - c0:12.3f} {100 * lag:8.2f}%"
        print(f"{frame + 1:5d} {t1 - t0:9.3f} {t2 - t1:12.3f} {t3 - t2:7.3f} {cold:>23}  {'; '.join(report['redone'])}")
        name = os.path.join(args.out, f"frame_{frame:03d}")
        haze.write_exr(name + ".exr", image)
        haze.write_png(name + ".png", image)
        previews.append(name + ".png")
    try:
        from PIL import Image
        frames = [Image.open(p).convert("P", palette=Image.ADAPTIVE) for p in previews]
        frames[0].save(os.path.join(args.out, "smoke.gif"), save_all=True, append_images=frames[1:], duration=80, loop=0)
        print(f"wrote {len(frames)} frames and {os.path.join(args.out, 'smoke.gif')}")
    except ImportError:
        print(f"wrote {len(previews)} frames (no Pillow: no GIF)")


if __name__ == "__main__":
    main()
