#version 460
// UV stretch (d'Eon & Luebke, GPU Gems 3 §14.4.3), extended to the UV shear: the
// metric of the parametrisation in the form the blur steps by (skin/stretch.rs).
// In UV space a = dFdx(P) is ∂P/∂u per texel and b = dFdy(P) ∂P/∂v (mm); the
// first fundamental form is M = [[E, F], [F, G]] = [[a·a, a·b], [a·b, b·b]]
// (mm² per texel²). Stored, in texels per mm (the range today's stretch had):
//   r = 1/|a|                texels of u per mm along a (the U pass's stretch)
//   g = 1/|b⊥|, b⊥ = b − (F/E)·a, the part of b perpendicular to a on the surface
//   b = −(F/E)/|b⊥|          texels of u per mm along b⊥
// so the V pass steps (b, g) texels per mm of surface along b⊥: the two passes
// are orthogonal on the surface, and M⁻¹ = U·Uᵀ with U = [[r, b], [0, g]]
// (its upper Cholesky-like factor). Without shear (F = 0) this is (1/|a|, 1/|b|, 0),
// the old stretch map, bit for bit. `shear = 0` keeps that diagonal (the UV
// shear ignored: skin.shear_correction = false).
// Alpha is coverage: blurs are normalised by it (see skin/blur.rs).
layout(push_constant) uniform Push {
    float constant_stretch;   // > 0: stretch correction off
    uint shear;               // 1: shear correction on
} pc;
layout(location = 0) in vec3 v_position;
// Declared to match uv.vert's outputs; unused here.
layout(location = 1) in vec3 v_normal;
layout(location = 2) in vec2 v_uv;
layout(location = 3) in vec4 v_tangent;
layout(location = 0) out vec4 stretch;

void main() {
    if (pc.constant_stretch > 0.0) {
        stretch = vec4(pc.constant_stretch, pc.constant_stretch, 0.0, 1.0);
        return;
    }
    vec3 a = dFdx(v_position);
    vec3 b = dFdy(v_position);
    float su = 1.0 / max(length(a), 1e-6);
    if (pc.shear == 0u) {
        float sv = 1.0 / max(length(b), 1e-6);
        stretch = vec4(su, sv, 0.0, 1.0);
        return;
    }
    float e = dot(a, a);
    float f = dot(a, b);
    float k = e > 1e-12 ? f / e : 0.0;
    float sv = 1.0 / max(length(b - k * a), 1e-6);
    stretch = vec4(su, sv, -k * sv, 1.0);
}
