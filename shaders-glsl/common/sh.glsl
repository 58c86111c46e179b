// Irradiance from 9 SH coefficients per channel: Ramamoorthi & Hanrahan 2001, eq. 13,
// with c1..c5 from their eq. 12. The basis is evaluated on world x, y, z (see light/sh.rs).
const float C1 = 0.429043;
const float C2 = 0.511664;
const float C3 = 0.743125;
const float C4 = 0.886227;
const float C5 = 0.247708;

vec3 sh_irradiance(vec4 L[9], vec3 n) {
    float x = n.x, y = n.y, z = n.z;
    return C1 * L[8].rgb * (x * x - y * y) + C3 * L[6].rgb * z * z + C4 * L[0].rgb - C5 * L[6].rgb
         + 2.0 * C1 * (L[4].rgb * x * y + L[7].rgb * x * z + L[5].rgb * y * z)
         + 2.0 * C2 * (L[3].rgb * x + L[1].rgb * y + L[2].rgb * z);
}

// The irradiance of SH radiance sh through a transfer t (Yang et al.'s eq. 13:
// E = Σ L_i·T_i; linear in t, so interpolating the transfer or the
// irradiance between vertices gives the same).
vec3 sh_transferred(vec4 sh[9], vec3 t012, vec3 t345, vec3 t678) {
    return sh[0].rgb * t012.x + sh[1].rgb * t012.y + sh[2].rgb * t012.z
         + sh[3].rgb * t345.x + sh[4].rgb * t345.y + sh[5].rgb * t345.z
         + sh[6].rgb * t678.x + sh[7].rgb * t678.y + sh[8].rgb * t678.z;
}
