// Schlick's Fresnel for skin's oil layer (skin/specular.rs::fresnel_schlick). F0
// is the renderer's (skin::SkinSettings::f0): d'Eon's 0.028 (n ≈ 1.4, GPU Gems 3
// §14.3) for the paper's lobe, ((n−1)/(n+1))² of a medium's boundary.

float fresnel_schlick(float h_dot_v, float f0) {
    float base = 1.0 - h_dot_v;
    return f0 + (1.0 - f0) * base * base * base * base * base;
}
