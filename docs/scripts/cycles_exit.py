"""Cycles' subsurface exit against a Lambertian one, per pixel (docs/records/2026-11-26-path-tracer-cycles.md,
"The colour where nothing bounces: the reference's exit").

    PY=/work/bpy-venv/bin/python; S=docs/scripts/cycles_reference.py
    $PY $S --out slab.json --slab-reflectance --sss-method skin --width 32 --height 32 --samples 512
    $PY $S --out normals.exr --normal-pass --sss off --bounces 0 --samples 16
    $PY $S --out albedo.exr --view albedo --samples 4
    dermis render --scene docs/scenes/cycles-uniform.toml --out d.exr
    dermis render --scene docs/scenes/cycles-uniform.toml --view specular --out spec.exr
    $PY docs/scripts/cycles_exit.py --dermis d.exr --cycles ref1.exr ref2.exr \\
        --exit-table slab.json --albedo albedo.exr --normals normals.exr --specular spec.exr

The slab table (cycles_reference.py --slab-reflectance) holds the radiance
L(mu; base) of a flat slab of base colour `base` under a uniform sky of 1, at
four exit cosines mu (Gauss-Legendre nodes); a Lambertian surface of albedo a
gives L = a. Each pixel's ratio r = L(mu; a) / a is read from it with the
pixel's albedo per channel (--albedo: Cycles' `--view albedo` or dermis's
`--view albedo`, linear) and exit cosine mu = n.v (--normals: Cycles' Normal
pass from `--normal-pass`, the shading normal with the normal map; or dermis's
`--view normals`; v from the Position pass's surface point to the camera).
L is interpolated linearly in base (clamped to the table's range) and
piecewise linearly in mu between the nodes, extrapolated linearly from the end
segments below the first node and above the last (--mu-ends clamp: held at the
end nodes' values instead).

If the image given as --dermis had a Lambertian exit and Cycles differed from
it only by r, Cycles would be S + D r, with D the diffuse part and S the part r
does not touch: the specular, estimated by dermis's `--view specular`
(--specular; without it S = 0). Per group of pixels (cycles_compare.py's) the
script prints the measured bias sum(dermis - ref)/sum(ref) per channel, the
bias this predicts, sum(dermis)/sum(S + D r) - 1 with D = dermis - S, and, as a
diagnostic, the comparison against Cycles put back on a Lambertian exit,
S + (ref - S)/r: mean relative error of luminance (the floor of the
uncorrected comparison), level and bias, as cycles_compare.py computes them.
"""

import argparse
import json
import os
import sys

import numpy as np
import OpenEXR

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cycles_compare as cc  # noqa: E402

# docs/scenes/cycles-uniform.toml's camera (cycles_reference.py's default), mm.
CAMERA_MM = (229.0, 119.0, 629.0)


class ExitTable:
    """The slab's radiance per exit cosine and base colour (one channel's
    Lambertian albedo in, Cycles' radiance over it out)."""

    def __init__(self, path, mu_ends):
        with open(path) as f:
            t = json.load(f)
        self.base = np.asarray(t["base"], np.float64)
        self.mu = np.asarray(t["mu"], np.float64)
        self.radiance = np.asarray(t["radiance"], np.float64)  # [mu][base]
        if self.radiance.shape != (len(self.mu), len(self.base)):
            raise SystemExit(f"{path}: radiance is not mu x base")
        self.mu_ends = mu_ends

    def ratio(self, albedo, mu):
        """r = L(mu; albedo) / albedo, elementwise (same shapes)."""
        a = np.clip(albedo, self.base[0], self.base[-1])
        per_node = np.stack([np.interp(a, self.base, row) / a for row in self.radiance])
        m = np.clip(mu, 0.0, 1.0)
        if self.mu_ends == "clamp":
            m = np.clip(m, self.mu[0], self.mu[-1])
        k = np.clip(np.searchsorted(self.mu, m) - 1, 0, len(self.mu) - 2)
        t = (m - self.mu[k]) / (self.mu[k + 1] - self.mu[k])
        lo = np.take_along_axis(per_node, k[None], 0)[0]
        hi = np.take_along_axis(per_node, (k + 1)[None], 0)[0]
        return lo + t * (hi - lo)


def read_normals(path):
    """World normals in dermis's axes (Y up), unit length: a Cycles EXR's Normal
    pass (Blender axes) or dermis's `--view normals` (0.5 n + 0.5)."""
    ch = OpenEXR.File(path).parts[0].channels
    if "ViewLayer.Normal.X" in ch:
        n = np.stack([ch[f"ViewLayer.Normal.{c}"].pixels for c in "XYZ"], -1).astype(np.float64)
        n = np.stack([n[..., 0], n[..., 2], -n[..., 1]], -1)  # as cc.read_cycles
    else:
        n = cc.read_dermis(path)[..., :3] * 2.0 - 1.0
    return n / np.maximum(np.linalg.norm(n, axis=-1, keepdims=True), 1e-12)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--dermis", required=True, help="the image with a Lambertian exit (.exr)")
    p.add_argument("--cycles", required=True, nargs="+", help="Cycles references (seeds)")
    p.add_argument("--exit-table", required=True, help="cycles_reference.py --slab-reflectance's JSON")
    p.add_argument("--albedo", required=True, help="linear albedo per pixel (.exr)")
    p.add_argument("--normals", required=True, help="Cycles --normal-pass EXR or dermis --view normals")
    p.add_argument("--specular", help="dermis --view specular: the part r does not scale")
    p.add_argument("--camera-mm", default=",".join(str(c) for c in CAMERA_MM))
    p.add_argument("--mu-ends", choices=["linear", "clamp"], default="linear")
    p.add_argument("--json", help="write the figures as JSON")
    args = p.parse_args()
    inputs = [args.dermis, args.exit_table, args.albedo, args.normals] + args.cycles
    for f in inputs + ([args.specular] if args.specular else []):
        if not os.path.isfile(f):
            p.error(f"no file {f}")

    dermis = cc.read_dermis(args.dermis)
    refs = [cc.read_cycles(f) for f in args.cycles]
    images = {"albedo": cc.read_dermis(args.albedo), "normals": read_normals(args.normals)}
    if args.specular:
        images["specular"] = cc.read_dermis(args.specular)
    for name, img in [(f, r) for f, (r, _) in zip(args.cycles, refs)] + list(images.items()):
        if img.shape[:2] != dermis.shape[:2]:
            p.error(f"sizes differ: dermis {dermis.shape[:2]}, {name} {img.shape[:2]}")
    ref = np.mean([r for r, _ in refs], 0)
    pos = refs[0][1]
    mask = cc.covered(dermis, ref)
    d, c = dermis[mask][:, :3], ref[mask][:, :3]
    s = images["specular"][mask][:, :3] if args.specular else np.zeros_like(d)
    albedo = images["albedo"][mask][:, :3]
    camera = np.array([float(x) for x in args.camera_mm.split(",")])
    view = camera - pos[mask]
    view /= np.linalg.norm(view, axis=-1, keepdims=True)
    mu = (images["normals"][mask] * view).sum(-1)
    table = ExitTable(args.exit_table, args.mu_ends)
    r = table.ratio(albedo, np.repeat(mu[:, None], 3, 1))

    predicted = s + (d - s) * r  # Cycles, if dermis's exit were Lambertian
    corrected = s + (c - s) / r  # Cycles put back on a Lambertian exit
    floor = 0.1 * cc.luminance(c).mean()
    _, groups = cc.region_groups(pos[mask] - cc.NOSE_TIP_MM)
    result = {
        "pixels": int(mask.sum()),
        "mu_below_first_node": float((mu < table.mu[0]).mean()),
        "mu_above_last_node": float((mu > table.mu[-1]).mean()),
        "groups": {},
    }
    for name, g in groups.items():
        if g.sum() == 0:
            continue
        measured = cc.stats(d[g], c[g], floor)
        result["groups"][name] = {
            "pixels": int(g.sum()),
            "mean_mu": float(mu[g].mean()),
            "mean_albedo": [float(x) for x in albedo[g].mean(0)],
            "mean_r": [float(x) for x in r[g].mean(0)],
            "measured": measured,
            "predicted_bias_rgb": [float(x) for x in d[g].sum(0) / predicted[g].sum(0) - 1],
            "predicted_level": float(cc.luminance(d[g].sum(0)) / cc.luminance(predicted[g].sum(0))),
            "corrected": cc.stats(d[g], corrected[g], floor),
        }

    print(f"{mask.sum()} pixels; mu below the first node {100 * result['mu_below_first_node']:.1f} %, "
          f"above the last {100 * result['mu_above_last_node']:.1f} %")
    pct = lambda v: " / ".join(f"{100 * x:+.1f}" for x in v)  # noqa: E731
    print(f"{'group':22s} {'pixels':>6s} {'mu':>5s}  {'r R / G / B':19s} {'measured bias':19s} {'predicted bias':19s} "
          f"{'level m/p':11s} | corrected: {'mean':>6s} {'level':>6s} bias")
    for name, g in result["groups"].items():
        m, k = g["measured"], g["corrected"]
        rr = " / ".join(f"{x:.3f}" for x in g["mean_r"])
        print(f"{name:22s} {g['pixels']:6d} {g['mean_mu']:5.2f}  {rr:19s} {pct(m['bias_rgb']):19s} "
              f"{pct(g['predicted_bias_rgb']):19s} {m['level']:.3f}/{g['predicted_level']:.3f} | "
              f"{100 * k['mean_rel_error']:9.2f}% {k['level']:.3f}  {pct(k['bias_rgb'])} %")
    if args.json:
        cc.write_atomic(args.json, json.dumps(result, indent=1).encode())
    return 0


if __name__ == "__main__":
    sys.exit(main())
