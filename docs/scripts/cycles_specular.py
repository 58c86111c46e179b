"""dermis's specular against the Cycles reference's specular layer, per region
(docs/records/2026-11-26-path-tracer-cycles.md, "The specular against the reference's").

    /work/bpy-venv/bin/python docs/scripts/cycles_specular.py \
        --dermis spec.exr --dermis-open spec_open.exr --normals normals.exr \
        --cycles layer1.exr layer2.exr --cycles-open open1.exr open2.exr \
        --cycles-skin skin1.exr skin2.exr --rho-s rho.exr [--slabs DIR]

dermis: `--view specular` with occlusion (spec.exr) and `--occlusion off`
(spec_open.exr), `--view normals` (normals.exr). Cycles (cycles_reference.py):
the layer alone under the sky, `--base black --bounces 0` (layer*.exr; what the
head hides is black), the same with `--occlusion off` (open*.exr), and the layer
reflecting the lit skin, `--base black-to-camera --sss off --bounces 8`
(skin*.exr); `--view rho-s` (rho.exr), the rho_s both renderers use. Seeds are
averaged. Per region (cycles_compare.py's groups): the mean specular radiance
(channel mean) of each; unoccluded, the lobes alone; occluded over unoccluded,
each renderer's visibility of the environment's specular.

--slabs DIR: DIR/slab_{map,dielectric}_MU.exr, a black slab (`--slab 0,0,0
--base black --sss off --bounces 0 --slab-mu MU --specular map|dielectric`) at
the exit cosines below, against quadratures of the lobes: dermis's KS at rho_s
0.26 (the slab's), single-scattering GGX (Cycles' lobe) and Beckmann with
height-correlated Smith masking, exact dielectric Fresnel, at alpha = m = 0.3.
"""

import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cycles_compare import NOSE_TIP_MM, read_cycles, read_dermis, region_groups  # noqa: E402

M = 0.3  # Beckmann m of every region (skin::specular::DEFAULT_M) = GGX alpha
F0 = 0.028  # skin::specular::F0_SKIN
SLAB_RHO_S = 0.18 * (1 + 0.5 * 0.16 / 0.18)  # cycles_reference.py's slab: t = 1/2
SLAB_MUS = [1.0, 0.8, 0.6, 0.4, 0.25, 0.12]
CAMERA_MM = np.array([229.0, 119.0, 629.0])  # assets/default.toml
REGIONS = [
    "mesh",
    "forehead",
    "nose",
    "chin",
    "left cheek",
    "right cheek",
    "eyelids/around eyes",
    "upper lip",
    "lower lip",
    "nostrils",
    "neck sides",
    "ears",
]


def light_grid(mu, n_t=1500, n_p=720):
    """Light directions over the hemisphere (midpoints in cos theta and phi),
    the solid angle of each, and the view at exit cosine mu."""
    c = (np.arange(n_t) + 0.5) / n_t
    p = (np.arange(n_p) + 0.5) / n_p * 2 * np.pi
    cos, phi = np.meshgrid(c, p, indexing="ij")
    sin = np.sqrt(1 - cos * cos)
    l = np.stack([sin * np.cos(phi), sin * np.sin(phi), cos], -1)
    v = np.array([np.sqrt(1 - mu * mu), 0.0, mu])
    h = l + v
    return l, v, h, 2 * np.pi / (n_t * n_p)


def fresnel_dielectric(c, eta):
    g = np.sqrt(np.maximum(eta * eta - 1 + c * c, 0))
    return 0.5 * ((g - c) / (g + c)) ** 2 * (1 + ((c * (g + c) - 1) / (c * (g - c) + 1)) ** 2)


def ks_albedo(mu, m=M):
    """skin::specular::specular_albedo: A = int N.L PH F / (h.h) dw_L, PH = pi D."""
    l, v, h, dw = light_grid(mu)
    hh = (h * h).sum(-1)
    nh = h[..., 2] / np.sqrt(hh)
    ph = np.exp(-(1 - nh * nh) / (nh * nh * m * m)) / (m * m * nh**4)
    e = (1 - (h * v).sum(-1) / np.sqrt(hh)).clip(0, 1) ** 5
    return float((l[..., 2] * ph * (e + F0 * (1 - e)) / hh).sum() * dw)


def microfacet_albedo(mu, alpha, eta, ggx):
    """int D F G2 / (4 N.V) dw_L, normalised D (GGX or Beckmann), height-correlated
    Smith G2 of the same distribution, exact dielectric Fresnel at eta."""
    l, v, h, dw = light_grid(mu)
    hn = h / np.linalg.norm(h, axis=-1, keepdims=True)
    nh = hn[..., 2]
    a2 = alpha * alpha
    if ggx:
        d = a2 / (np.pi * (nh * nh * (a2 - 1) + 1) ** 2)

        def lam(c):
            return (-1 + np.sqrt(1 + a2 * (1 - c * c) / (c * c))) / 2

    else:
        d = np.exp(-(1 - nh * nh) / (nh * nh * a2)) / (np.pi * a2 * nh**4)

        def lam(c):
            a = c / (alpha * np.sqrt(np.maximum(1 - c * c, 1e-12)))
            t = 1 / (1 + 0.3275911 * a)  # erf: Abramowitz & Stegun 7.1.26
            poly = [1.061405429, -1.453152027, 1.421413741, -0.284496736, 0.254829592, 0.0]
            erf = 1 - np.polyval(poly, t) * np.exp(-a * a)
            return np.where(c >= 1, 0.0, (erf - 1) / 2 + np.exp(-a * a) / (2 * a * np.sqrt(np.pi)))

    f = fresnel_dielectric((hn * v).sum(-1), eta)
    g2 = 1 / (1 + lam(l[..., 2]) + lam(np.float64(mu)))
    return float((d * f * g2 / (4 * mu)).sum() * dw)


def eta_of_level(rho_s):
    """The IOR Cycles' Principled uses at Specular IOR Level 0.5 rho_s / 0.35:
    F0 scaled by 2 x level, then eta from F0."""
    f0 = ((1.4 - 1) / (1.4 + 1)) ** 2 * rho_s / 0.35
    return (1 + np.sqrt(f0)) / (1 - np.sqrt(f0))


def slabs(folder):
    import OpenEXR

    def mean(path):
        px = OpenEXR.File(path).parts[0].channels["ViewLayer.Combined"].pixels
        return float(px[..., :3].astype(np.float64).mean())

    eta = eta_of_level(SLAB_RHO_S)
    print(f"black slab, rho_s {SLAB_RHO_S:.3f} (Cycles eta {eta:.3f}), m = alpha = {M}")
    print("| μ | Cycles, level | GGX, eta | KS, ρs | KS / Cycles | Cycles, IOR 1.4 | GGX, 1.4 | Beckmann, 1.4 |")
    print("|---|---|---|---|---|---|---|---|")
    for mu in SLAB_MUS:
        c_map = mean(os.path.join(folder, f"slab_map_{mu:g}.exr"))
        c_diel = mean(os.path.join(folder, f"slab_dielectric_{mu:g}.exr"))
        ks = SLAB_RHO_S * ks_albedo(mu)
        print(
            f"| {mu:g} | {c_map:.4f} | {microfacet_albedo(mu, M, eta, True):.4f} | {ks:.4f} "
            f"| {ks / c_map:.2f} | {c_diel:.4f} | {microfacet_albedo(mu, M, 1.4, True):.4f} "
            f"| {microfacet_albedo(mu, M, 1.4, False):.4f} |"
        )


def mean_of(paths, read):
    return np.mean([read(p) for p in paths], 0)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--dermis", required=True)
    p.add_argument("--dermis-open", required=True)
    p.add_argument("--normals", required=True, help="dermis --view normals (0.5 n + 0.5)")
    p.add_argument("--cycles", nargs="+", required=True)
    p.add_argument("--cycles-open", nargs="+", required=True)
    p.add_argument("--cycles-skin", nargs="+", required=True)
    p.add_argument("--rho-s", required=True)
    p.add_argument("--slabs", help="folder of slab_{map,dielectric}_MU.exr")
    a = p.parse_args()

    d4 = read_dermis(a.dermis)
    d = d4[..., :3].mean(-1)
    d_open = read_dermis(a.dermis_open)[..., :3].mean(-1)
    _, pos = read_cycles(a.cycles[0])
    c4 = mean_of(a.cycles, lambda f: read_cycles(f)[0])
    c = c4[..., :3].mean(-1)
    c_open = mean_of(a.cycles_open, lambda f: read_cycles(f)[0])[..., :3].mean(-1)
    c_skin = mean_of(a.cycles_skin, lambda f: read_cycles(f)[0])[..., :3]
    rho = read_cycles(a.rho_s)[0][..., 0]
    n = read_dermis(a.normals)[..., :3] * 2 - 1
    n /= np.maximum(np.linalg.norm(n, axis=-1, keepdims=True), 1e-9)
    v = CAMERA_MM - pos
    v /= np.linalg.norm(v, axis=-1, keepdims=True)
    mu = (n * v).sum(-1)
    cov = (c4[..., 3] > 0.999) & (d4[..., 3] > 0.5)
    # dermis's unoccluded specular from the inputs: rho_s A(mu, m), A tabulated.
    mus = np.linspace(0.0, 1.0, 41)
    table = [ks_albedo(max(x, 0.005)) for x in mus]
    ks = rho * np.interp(np.clip(mu, 0.0, 1.0), mus, table)
    _, groups = region_groups(pos[cov] - NOSE_TIP_MM)

    print(
        "| region | pixels | ρs | μ | dermis | Cycles | ratio | unoccluded: dermis (ρs·A(μ)) / Cycles / ratio "
        "| visibility: dermis / Cycles / ratio | Cycles reflecting the skin R / G / B | dermis / that | R / G / B |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for name in REGIONS:
        s = groups[name]

        def f(im):
            return im[cov][s].mean(0)

        dv, cv = f(d) / f(d_open), f(c) / f(c_open)
        skin = f(c_skin)
        per = f(d4[..., :3]) / skin
        print(
            f"| {name} | {s.sum()} | {f(rho):.3f} | {f(mu):.2f} | {f(d):.4f} | {f(c):.4f} "
            f"| **{f(d) / f(c):.2f}** | {f(d_open):.4f} ({f(ks):.4f}) / {f(c_open):.4f} / {f(d_open) / f(c_open):.2f} "
            f"| {dv:.2f} / {cv:.2f} / **{dv / cv:.2f}** "
            f"| {skin[0]:.4f} / {skin[1]:.4f} / {skin[2]:.4f} | {f(d) / skin.mean():.2f} "
            f"| {per[0]:.2f} / {per[1]:.2f} / {per[2]:.2f} |"
        )
    if a.slabs:
        print()
        slabs(a.slabs)


if __name__ == "__main__":
    main()
