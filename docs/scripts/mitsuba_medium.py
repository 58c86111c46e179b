#!/usr/bin/env python3
"""The scanned head as a homogeneous medium in a volumetric path tracer
(Mitsuba 3): the truth dermis's `[skin.medium]` is held to (docs/design/media.md).

The mesh (assets/head/lee-perry-smith/LeePerrySmith.glb, 50.3 mm per unit, in
dermis's world: mm, +Y up) is the boundary of one homogeneous medium: a rough
dielectric (Beckmann alpha = the skin's roughness m, eta = ior) around a medium
of the given sigma_a and sigma_s_prime (mm^-1; isotropic, so sigma_s =
sigma_s_prime). Each colour channel is rendered as its own grey medium
(volpath samples distances from one channel, and the others' weights diverge
over long walks). The output is one EXR in the layout
docs/scripts/cycles_compare.py reads as a reference: Combined.{R,G,B,A} (linear
radiance, alpha = coverage) and Position.{X,Y,Z} (the first surface hit, dermis
world mm).

Scenes (match dermis's with the same camera, size and sky; docs/scenes/):
  uniform   a uniform sky of radiance 1 (docs/scenes/skin1-uniform.toml)
  backlit   the left side of the head under BACK_SKY: radiance 0.02 + 2·max(0, -z)^2,
            the light from behind the head (docs/scenes/skin1-backlit.toml, whose
            docs/scenes/back-sky.exr `--write-back-sky` writes)
Small or delta lights (a sun) cannot be compared this way: volpath reaches the
medium only by unidirectional paths (no shadow ray crosses the dielectric
boundary), so a directional light lights the boundary's reflection and never
the interior.

    pip install mitsuba
    DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM-19.so \\
    python3 docs/scripts/mitsuba_medium.py --scene uniform --spp 256 --seed 1 \\
        --out ref-uniform-1.exr

Uses the `llvm_ad_rgb` variant (Dr.Jit's LLVM backend: on Debian 12 it needs a
newer libLLVM than the system's 15, e.g. Debian's libllvm19, through
DRJIT_LIBLLVM_PATH); `--variant scalar_rgb` works without LLVM, slowly.
Units: mm, mm^-1.
"""
import argparse
import json
import os
import struct
import sys
import tempfile

import numpy as np

MM_PER_UNIT = 50.3
HERE = os.path.dirname(os.path.abspath(__file__))
GLB = os.path.join(HERE, "..", "..", "assets", "head", "lee-perry-smith", "LeePerrySmith.glb")
SCENES = {
    # camera position, target (mm), vertical field of view (deg), size, sky
    "uniform": ([229, 119, 629], [0, 60, 0], 30.0, (256, 320), "uniform"),
    "backlit": ([-400, 65, -10], [-80, 65, -10], 30.0, (256, 320), "back"),
}
BACK_SKY_SIZE = (256, 128)


def back_sky():
    """BACK_SKY as a lat-long map in dermis's convention (src/scene/env/map.rs:
    u = atan2(x, -z)/2pi + 0.5, v = acos(y)/pi), linear RGB, float32."""
    w, h = BACK_SKY_SIZE
    u = (np.arange(w) + 0.5) / w
    v = (np.arange(h) + 0.5) / h
    theta, phi = np.pi * v[:, None], 2 * np.pi * (u[None, :] - 0.5)
    z = -np.sin(theta) * np.cos(phi)
    radiance = 0.02 + 2.0 * np.maximum(0.0, -z) ** 2
    return np.repeat(radiance[..., None], 3, -1).astype(np.float32)


def write_exr(path, channels):
    import OpenEXR

    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    tmp = f"{path}.tmp-{os.getpid()}.exr"
    with OpenEXR.File(header, channels) as f:
        f.write(tmp)
    os.replace(tmp, path)


# Jensen et al. 2001, Table 2 (skin1), mm^-1.
SKIN1 = ([0.032, 0.17, 0.48], [0.74, 0.88, 1.01])


def read_glb(path):
    """Positions (mm), normals and triangles of the glb's one primitive."""
    with open(path, "rb") as f:
        data = f.read()
    magic, _, _ = struct.unpack("<III", data[:12])
    if magic != 0x46546C67:
        raise SystemExit(f"{path}: not a glb file")
    n = struct.unpack("<I", data[12:16])[0]
    gltf = json.loads(data[20 : 20 + n])
    binary = data[20 + n + 8 :]
    prim = gltf["meshes"][0]["primitives"][0]

    def accessor(i):
        a = gltf["accessors"][i]
        view = gltf["bufferViews"][a["bufferView"]]
        dtype = {5123: np.uint16, 5125: np.uint32, 5126: np.float32}[a["componentType"]]
        width = {"SCALAR": 1, "VEC2": 2, "VEC3": 3}[a["type"]]
        start = view.get("byteOffset", 0) + a.get("byteOffset", 0)
        return np.frombuffer(binary, dtype, a["count"] * width, start).reshape(a["count"], width)

    pos = accessor(prim["attributes"]["POSITION"]).astype(np.float64) * MM_PER_UNIT
    nrm = accessor(prim["attributes"]["NORMAL"]).astype(np.float64)
    tri = accessor(prim["indices"]).reshape(-1, 3).astype(np.uint32)
    return pos, nrm, tri


def write_ply(path, pos, nrm, tri):
    """Binary little-endian PLY with vertex normals (Mitsuba's `ply` shape)."""
    head = (
        "ply\nformat binary_little_endian 1.0\n"
        f"element vertex {len(pos)}\n"
        "property float x\nproperty float y\nproperty float z\n"
        "property float nx\nproperty float ny\nproperty float nz\n"
        f"element face {len(tri)}\nproperty list uchar int vertex_indices\nend_header\n"
    )
    verts = np.hstack([pos, nrm]).astype("<f4")
    faces = np.zeros(len(tri), dtype=[("n", "u1"), ("i", "<i4", 3)])
    faces["n"] = 3
    faces["i"] = tri
    with open(path, "wb") as f:
        f.write(head.encode())
        f.write(verts.tobytes())
        f.write(faces.tobytes())


def scene_dict(mi, ply, scene, channel, args, spp, seed, aov=False):
    origin, target, fov, (w, h), sky = SCENES[scene]
    if args.scale > 1:
        w, h = w // args.scale, h // args.scale
    sigma_a = args.sigma_a[channel]
    sigma_s = args.sigma_s_prime[channel] / (1.0 - args.g)
    sigma_t = sigma_a + sigma_s
    d = {
        "type": "scene",
        "integrator": (
            # A nested integrator gives the film its alpha (coverage, no emitters).
            {"type": "aov", "aovs": "pp:position", "nested": {"type": "direct"}}
            if aov
            else {"type": "volpath", "max_depth": -1, "rr_depth": 1 << 20}
        ),
        "sensor": {
            "type": "perspective",
            "fov": fov,
            "fov_axis": "y",
            "near_clip": 1.0,
            "far_clip": 10000.0,
            "to_world": mi.ScalarTransform4f().look_at(origin=origin, target=target, up=[0, 1, 0]),
            "film": {
                "type": "hdrfilm",
                "width": w,
                "height": h,
                "rfilter": {"type": "box"},
                "pixel_format": "rgba",
            },
            "sampler": {"type": "independent", "sample_count": spp, "seed": seed},
        },
        "head": {
            "type": "ply",
            "filename": ply,
            "bsdf": {
                "type": "roughdielectric",
                "distribution": "beckmann",
                "alpha": args.roughness,
                "int_ior": args.ior,
                "ext_ior": 1.0,
            },
            "interior": {
                "type": "homogeneous",
                "albedo": sigma_s / sigma_t,
                "sigma_t": sigma_t,
                "phase": {"type": "hg", "g": args.g} if args.g else {"type": "isotropic"},
            },
        },
    }
    if aov:
        # No emitters: the film's alpha is then the mesh's coverage.
        return d
    if sky == "uniform":
        d["sky"] = {"type": "constant", "radiance": {"type": "rgb", "value": [1.0] * 3}}
    else:
        # Mitsuba's envmap reads u = atan2(x, -z)/2pi: dermis's map turned by half.
        d["sky"] = {"type": "envmap", "filename": args.back_sky_mitsuba}
    return d


def render(mi, ply, args, channel, seed):
    scene = mi.load_dict(scene_dict(mi, ply, args.scene, channel, args, args.spp, seed))
    return np.array(mi.render(scene, seed=seed))[..., 0]


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--scene", choices=sorted(SCENES))
    p.add_argument("--sigma-a", type=float, nargs=3, default=SKIN1[0])
    p.add_argument("--sigma-s-prime", type=float, nargs=3, default=SKIN1[1])
    p.add_argument("--g", type=float, default=0.0)
    p.add_argument("--ior", type=float, default=1.4)
    p.add_argument("--roughness", type=float, default=0.3, help="Beckmann alpha (the skin's m)")
    p.add_argument("--spp", type=int, default=256)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--scale", type=int, default=1,
                   help="render at 1/SCALE of the size: each pixel then averages SCALE x SCALE "
                   "of dermis's (cycles_compare.py --bins BINS/SCALE at the same bins)")
    p.add_argument("--variant", default="llvm_ad_rgb")
    p.add_argument("--out", help="the reference EXR")
    p.add_argument("--write-back-sky", metavar="EXR",
                   help="write BACK_SKY in dermis's convention (docs/scenes/back-sky.exr) and exit")
    p.add_argument("--specular-only", action="store_true",
                   help="an interior that absorbs all it is given: the boundary's reflection "
                   "alone (dermis: docs/scenes/skin1-boundary.toml, whose interior absorbs too)")
    args = p.parse_args()
    if args.write_back_sky:
        write_exr(args.write_back_sky, {"RGB": back_sky()})
        print(f"wrote {args.write_back_sky}")
        return 0
    if not args.out or not args.out.endswith(".exr"):
        p.error("--out must end in .exr")
    if not args.scene:
        p.error("--scene is required")
    if not os.path.isdir(os.path.dirname(os.path.abspath(args.out))):
        p.error(f"no folder for {args.out}")
    if not (0 <= args.g < 1 and args.ior > 1 and args.roughness > 0 and args.spp > 0):
        p.error("need 0 <= g < 1, ior > 1, roughness > 0, spp > 0")
    if not os.path.isfile(GLB):
        p.error(f"no mesh {GLB}")

    import mitsuba as mi

    mi.set_variant(args.variant)
    pos, nrm, tri = read_glb(GLB)
    with tempfile.TemporaryDirectory() as tmp:
        ply = os.path.join(tmp, "head.ply")
        write_ply(ply, pos, nrm, tri)
        args.back_sky_mitsuba = os.path.join(tmp, "back-sky.exr")
        write_exr(args.back_sky_mitsuba, {"RGB": np.roll(back_sky(), BACK_SKY_SIZE[0] // 2, axis=1)})
        if args.specular_only:
            # An interior that absorbs what enters within 0.01 mm: what leaves
            # is the boundary's reflection alone.
            args.sigma_a = [100.0] * 3
            args.sigma_s_prime = [0.0] * 3
        aov = mi.load_dict(scene_dict(mi, ply, args.scene, 0, args, 64, args.seed, aov=True))
        # The aov film: R, G, B, A of the (empty) nested result, then the position.
        pp = np.array(mi.render(aov, seed=args.seed))
        alpha = pp[..., 3]
        channels = []
        for c in range(3):
            v = render(mi, ply, args, c, args.seed * 3 + c)
            channels.append(v)
            print(f"channel {'RGB'[c]}: mean {v[alpha > 0.999].mean():.5f}", file=sys.stderr)
    rgba = np.stack(channels + [alpha], -1).astype(np.float32)
    # Where the mesh covers a pixel only partly, the mean position is of its hits.
    position = (pp[..., -3:] / np.maximum(alpha, 1e-6)[..., None]).astype(np.float32)
    write_exr(args.out, {"Combined": rgba, "Position": position})
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
