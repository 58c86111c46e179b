"""Compare a dermis render with a Cycles reference (docs/scripts/cycles_reference.py).

    /work/bpy-venv/bin/python docs/scripts/cycles_compare.py \
        --dermis dermis.exr --cycles ref1.exr [ref2.exr ...] [--png fig.png] [--regions-png r.png]

dermis.exr: `dermis render --out X.exr` (linear, alpha = coverage) at the
references' size and camera; each reference: the multilayer EXR the script
writes (Combined and Position). Several references (seeds) are averaged; with
two or more the script also gives their noise, and the mesh's RMS relative
error with that noise taken out (from the first two seeds). Pixels count where the mesh
covers the whole pixel in both (Cycles alpha > 0.999, dermis alpha > 0.5).

Per group of pixels: the mean relative error of luminance (Rec. 709), each
pixel's |dermis - ref| / max(ref, 0.1 x the mesh's mean), dermis's metric
(sweep::metric::relative); the level, sum(dermis)/sum(ref) of luminance; the
bias per channel, sum(dermis - ref)/sum(ref). Groups are face regions by the
pixel's surface point (the Position pass) about the nose tip: the boxes of
dermis's fidelity::diffusion_gap::landmark_region, plus a few of this script's own
(nostrils, lip line, neck sides, chest), checked by eye on --regions-png.
"""

import argparse
import json
import os
import struct
import sys
import zlib

import numpy as np
import OpenEXR

MM_PER_UNIT = 50.3
# The scan's most +z vertex (dermis world mm, +Y up), as fidelity::diffusion_gap's
# region_ids takes it: bpy's import of LeePerrySmith.glb, x 50.3 mm.
NOSE_TIP_MM = np.array([-4.42, 55.20, 130.30])
LANDMARK_NAMES = [
    "forehead",
    "nose",
    "left cheek",
    "right cheek",
    "chin",
    "eyelids/around eyes",
    "upper lip",
    "lower lip",
    "ears",
    "neck/other",
]


def landmark_region(d):
    """fidelity::diffusion_gap::landmark_region, vectorised: d (N, 3) mm from the tip."""
    x, y, z = np.abs(d[:, 0]), d[:, 1], d[:, 2]

    def within(v, lo, hi):
        return (v >= lo) & (v <= hi)

    boxes = [
        ("ears", (x > 75) & within(y, -25, 50) & within(z, -180, -95)),
        ("nose", (x < 17) & within(y, -22, 32) & (z > -32)),
        ("eyelids/around eyes", within(x, 12, 52) & within(y, 22, 50) & (z > -55)),
        ("forehead", (x < 50) & within(y, 50, 110) & (z > -65)),
        ("upper lip", (x < 27) & within(y, -35, -18) & (z > -40)),
        ("lower lip", (x < 27) & within(y, -52, -35) & (z > -45)),
        ("chin", (x < 30) & within(y, -90, -52) & (z > -60)),
        ("cheek", within(x, 17, 65) & within(y, -40, 22) & (z > -75)),
    ]
    region = np.full(len(d), LANDMARK_NAMES.index("neck/other"))
    unset = np.ones(len(d), bool)
    for name, inside in boxes:
        take = unset & inside
        if name == "cheek":
            ids = np.where(d[:, 0] > 0, 2, 3)
            region[take] = ids[take]
        else:
            region[take] = LANDMARK_NAMES.index(name)
        unset &= ~inside
    return region


def extra_groups(d):
    """This script's own boxes (mm from the tip; x mirrored), for the issue's
    regions the landmark boxes do not name."""
    x, y, z = np.abs(d[:, 0]), d[:, 1], d[:, 2]
    return {
        # The nose's underside: below the tip and behind it.
        "nostrils": (x < 17) & (y > -22) & (y < -6) & (z > -32) & (z < -6),
        # A band 10 mm high across the mouth's line.
        "lip line": (x < 27) & (y > -40) & (y < -30) & (z > -45),
        # The neck below the jaw, to the side of the throat.
        "neck sides": (x > 30) & (x < 75) & (y > -170) & (y < -95) & (z > -120),
        # The front below the neck.
        "chest": (y < -175) & (z > -110),
    }


def covered(dermis, ref):
    """The pixels both images cover fully: Cycles alpha > 0.999, dermis alpha > 0.5."""
    return (ref[..., 3] > 0.999) & (dermis[..., 3] > 0.5)


def region_groups(offset):
    """The landmark region id per pixel and the named groups of pixels (boolean
    masks): mesh, face, the landmark regions and extra_groups', from the surface
    points' offset (N, 3) in mm from the nose tip."""
    region = landmark_region(offset)
    groups = {"mesh": np.ones(len(offset), bool), "face": region < LANDMARK_NAMES.index("ears")}
    for i, name in enumerate(LANDMARK_NAMES):
        groups[name] = region == i
    groups.update(extra_groups(offset))
    return region, groups


def read_dermis(path):
    """dermis's EXR (RGBA), or a Cycles one (Combined), to compare two variants."""
    ch = OpenEXR.File(path).parts[0].channels
    if "ViewLayer.Combined" in ch:
        return ch["ViewLayer.Combined"].pixels.astype(np.float64)
    if "RGBA" in ch:
        return ch["RGBA"].pixels.astype(np.float64)
    return np.stack([ch[c].pixels for c in "RGBA"], -1).astype(np.float64)


def read_cycles(path):
    ch = OpenEXR.File(path).parts[0].channels
    if "Combined" in ch:
        # docs/scripts/mitsuba_medium.py: positions in dermis world mm already.
        return ch["Combined"].pixels.astype(np.float64), ch["Position"].pixels.astype(np.float64)
    rgba = ch["ViewLayer.Combined"].pixels.astype(np.float64)
    pos = np.stack([ch[f"ViewLayer.Position.{c}"].pixels for c in "XYZ"], -1)
    # Blender (units, Z up) to dermis (mm, Y up): (x, y, z) -> (x, z, -y).
    mm = np.stack([pos[..., 0], pos[..., 2], -pos[..., 1]], -1) * MM_PER_UNIT
    return rgba, mm.astype(np.float64)


def binned(image, k):
    """The mean over k x k blocks of pixels (a partial block at the edges is dropped)."""
    if k == 1:
        return image
    h, w = image.shape[0] // k * k, image.shape[1] // k * k
    return image[:h, :w].reshape(h // k, k, w // k, k, -1).mean((1, 3))


def luminance(rgb):
    return rgb @ np.array([0.2126, 0.7152, 0.0722])


def stats(dermis, ref, floor):
    ld, lr = luminance(dermis), luminance(ref)
    rel = np.abs(ld - lr) / np.maximum(lr, floor)
    return {
        "pixels": int(len(ld)),
        "mean_rel_error": float(rel.mean()),
        "p90_rel_error": float(np.percentile(rel, 90)),
        "level": float(ld.sum() / lr.sum()),
        "bias_rgb": [float(b) for b in (dermis - ref).sum(0) / ref.sum(0)],
    }


def write_png(path, rgb8):
    """8-bit RGB PNG (zlib, filter 0), written to a temporary file and renamed."""
    h, w, _ = rgb8.shape
    raw = b"".join(b"\0" + rgb8[j].tobytes() for j in range(h))

    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")
    write_atomic(path, png)


def write_atomic(path, data):
    tmp = os.path.join(os.path.dirname(os.path.abspath(path)), "." + os.path.basename(path) + ".tmp")
    try:
        with open(tmp, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)


def srgb8(linear):
    c = np.clip(linear, 0, 1)
    c = np.where(c <= 0.0031308, 12.92 * c, 1.055 * c ** (1 / 2.4) - 0.055)
    return (c * 255 + 0.5).astype(np.uint8)


def figure(dermis, ref, mask, scale):
    """dermis | reference | signed luminance difference (red: dermis brighter,
    blue: darker; full at +-scale relative)."""
    rel = np.zeros(mask.shape)
    lr = luminance(ref[..., :3])
    rel[mask] = (luminance(dermis[..., :3])[mask] - lr[mask]) / np.maximum(lr[mask], 1e-6)
    t = np.clip(rel / scale, -1, 1)
    diff = np.ones(mask.shape + (3,))
    diff[..., 1] = 1 - np.abs(t)
    diff[..., 0] = np.where(t < 0, 1 + t, 1)
    diff[..., 2] = np.where(t > 0, 1 - t, 1)
    diff[~mask] = 0.5
    panels = [srgb8(dermis[..., :3]), srgb8(ref[..., :3]), (diff * 255).astype(np.uint8)]
    return np.concatenate(panels, 1)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--dermis", required=True)
    p.add_argument("--cycles", required=True, nargs="+")
    p.add_argument("--json", help="write the figures as JSON")
    p.add_argument("--png", help="write dermis | reference | difference")
    p.add_argument("--diff-scale", type=float, default=0.2, help="difference at full colour")
    p.add_argument("--regions-png", help="write the region masks over the reference")
    p.add_argument(
        "--unlit",
        help="a dermis render (.exr) of the lights alone (e.g. --view direct under "
        "--env uniform:0,0,0): its black pixels, where no light reaches directly, "
        "form the groups 'unlit' and 'REGION unlit'",
    )
    p.add_argument(
        "--bins",
        type=int,
        default=1,
        help="compare means over BINS x BINS of dermis's pixels (a reference rendered at "
        "1/S of dermis's size is binned by BINS/S); a bin counts where both cover it whole",
    )
    args = p.parse_args()
    for f in [args.dermis] + args.cycles + ([args.unlit] if args.unlit else []):
        if not os.path.isfile(f):
            p.error(f"no file {f}")
    for out in (args.json, args.png, args.regions_png):
        if out and not os.path.isdir(os.path.dirname(os.path.abspath(out))):
            p.error(f"no folder for {out}")

    dermis = read_dermis(args.dermis)
    refs = [read_cycles(f) for f in args.cycles]
    scale = dermis.shape[0] // refs[0][0].shape[0]
    if args.bins % scale or dermis.shape[0] != scale * refs[0][0].shape[0]:
        p.error(f"dermis {dermis.shape[:2]} is not {args.bins}-binnable onto the reference "
                f"{refs[0][0].shape[:2]}")
    if args.bins > 1:
        # Coverage as the fraction of a bin covered (dermis's alpha > 0.5 per pixel).
        dermis[..., 3] = dermis[..., 3] > 0.5
        dermis = binned(dermis, args.bins)
        k = args.bins // scale
        refs = [(binned(rgba, k), binned(pos * rgba[..., 3:], k) / np.maximum(binned(rgba[..., 3:], k), 1e-9))
                for rgba, pos in refs]
        dermis[..., 3] = np.where(dermis[..., 3] > 0.999, 1.0, 0.0)
    for rgba, _ in refs:
        if rgba.shape != dermis.shape:
            p.error(f"sizes differ: dermis {dermis.shape[:2]}, Cycles {rgba.shape[:2]}")
    ref = np.mean([r for r, _ in refs], 0)
    pos = refs[0][1]
    mask = covered(dermis, ref)
    coverage_iou = float(
        ((ref[..., 3] > 0.5) & (dermis[..., 3] > 0.5)).sum()
        / ((ref[..., 3] > 0.5) | (dermis[..., 3] > 0.5)).sum()
    )
    d, r = dermis[mask][:, :3], ref[mask][:, :3]
    floor = 0.1 * luminance(r).mean()
    offset = pos[mask] - NOSE_TIP_MM
    region, groups = region_groups(offset)
    if args.unlit:
        unlit_image = read_dermis(args.unlit)
        if unlit_image.shape != dermis.shape:
            p.error(f"sizes differ: dermis {dermis.shape[:2]}, --unlit {unlit_image.shape[:2]}")
        unlit = luminance(unlit_image[mask][:, :3]) <= 0.0
        for name in list(groups):
            groups[f"{name} unlit" if name != "mesh" else "unlit"] = groups[name] & unlit

    result = {"coverage_iou": coverage_iou, "floor": floor, "groups": {}}
    if len(refs) >= 2:
        # Two seeds: the mean's standard error per pixel is |a - b| / 2 for two
        # (sqrt(pi/2) turns the mean |.| into sigma); reported relative.
        a, b = refs[0][0][mask][:, :3], refs[1][0][mask][:, :3]
        la, lb = luminance(a), luminance(b)
        se = np.sqrt(np.pi / 2) * np.abs(la - lb) / 2 / np.sqrt(len(refs) / 2)
        result["ref_noise_rel"] = float((se / np.maximum(luminance(r), floor)).mean())
        result["seed_level"] = float(la.sum() / lb.sum())
        # The RMS relative error without the reference's noise: for two
        # independent seeds E[(d - a)(d - b)] = (d - truth)^2.
        ld, f = luminance(d), np.maximum(luminance(r), floor)
        result["rms_rel"] = float(np.sqrt((((ld - luminance(r)) / f) ** 2).mean()))
        result["rms_rel_noise_free"] = float(np.sqrt(max(((ld - la) * (ld - lb) / f**2).mean(), 0.0)))
    for name, g in groups.items():
        if g.sum() == 0:
            continue
        result["groups"][name] = stats(d[g], r[g], floor)

    print(f"coverage IoU {coverage_iou:.4f}, {mask.sum()} pixels")
    if "ref_noise_rel" in result:
        print(f"reference noise (mean relative standard error per pixel) {100 * result['ref_noise_rel']:.2f} %, seed level ratio {result['seed_level']:.4f}")
        print(f"mesh RMS relative error {100 * result['rms_rel']:.2f} %, without the reference's noise {100 * result['rms_rel_noise_free']:.2f} % (first two seeds)")
    print(f"{'group':22s} {'pixels':>7s} {'mean':>7s} {'p90':>7s} {'level':>7s}   bias R / G / B")
    for name, s in result["groups"].items():
        bias = " / ".join(f"{100 * x:+.1f}" for x in s["bias_rgb"])
        print(f"{name:22s} {s['pixels']:7d} {100 * s['mean_rel_error']:6.2f}% {100 * s['p90_rel_error']:6.2f}% {s['level']:7.4f}   {bias} %")

    if args.json:
        write_atomic(args.json, json.dumps(result, indent=1).encode())
    if args.png:
        write_png(args.png, figure(dermis, ref, mask, args.diff_scale))
    if args.regions_png:
        palette = np.array(
            [[230, 25, 75], [60, 180, 75], [255, 225, 25], [0, 130, 200], [245, 130, 48],
             [145, 30, 180], [70, 240, 240], [240, 50, 230], [210, 245, 60], [128, 128, 128]]
        )
        img = srgb8(ref[..., :3]).astype(np.float64)
        tint = palette[region].astype(np.float64)
        extra = extra_groups(offset)
        for k, (name, g) in enumerate(extra.items()):
            tint[g] = [[255, 255, 255], [0, 0, 0], [255, 128, 0], [0, 0, 255]][k]
        flat = img[mask]
        img[mask] = 0.45 * flat + 0.55 * tint
        write_png(args.regions_png, img.astype(np.uint8))
    return 0


if __name__ == "__main__":
    sys.exit(main())
