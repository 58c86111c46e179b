#version 460
// UV stretch (d'Eon & Luebke, GPU Gems 3 §14.4.3): texels per millimetre along u
// and v, so that a blur width in mm times stretch is a tap spacing in texels.
// In UV space dFdx(P) is ∂P/∂u per texel (mm), so stretch = 1/|∂P/∂u|.
// Alpha is coverage: blurs are normalised by it (see skin/blur.rs).
layout(push_constant) uniform Push { float constant_stretch; } pc;   // > 0: correction off
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
    float su = 1.0 / max(length(dFdx(v_position)), 1e-6);
    float sv = 1.0 / max(length(dFdy(v_position)), 1e-6);
    stretch = vec4(su, sv, 0.0, 1.0);
}
