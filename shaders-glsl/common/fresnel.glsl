// Fresnel reflectance of the specular lobe (skin/specular.rs::Lobe).

// Schlick's, for skin's oil layer (skin/specular.rs::fresnel_schlick): F0 is
// d'Eon's 0.028 (n ≈ 1.4, GPU Gems 3 §14.3) for the paper's lobe.
float fresnel_schlick(float h_dot_v, float f0) {
    float base = 1.0 - h_dot_v;
    return f0 + (1.0 - f0) * base * base * base * base * base;
}

// The exact unpolarised reflectance of a dielectric of index `eta` > 1 seen
// from air (Walter et al. 2007, eq. 22; skin/walk.rs::fresnel_dielectric).
float fresnel_dielectric(float c, float eta) {
    float g = sqrt(max(eta * eta - 1.0 + c * c, 0.0));
    float a = (g - c) / (g + c);
    float b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0);
    return 0.5 * a * a * (1.0 + b * b);
}
