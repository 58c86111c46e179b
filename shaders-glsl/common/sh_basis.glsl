// Real SH basis for l <= 2 on world x, y, z (light/sh.rs; Ramamoorthi & Hanrahan
// 2001, Sloan "Stupid SH tricks"): L00, L1-1, L10, L11, L2-2, L2-1, L20, L21, L22.
void sh_basis(vec3 d, out float b[9]) {
    b[0] = 0.282095;
    b[1] = 0.488603 * d.y;
    b[2] = 0.488603 * d.z;
    b[3] = 0.488603 * d.x;
    b[4] = 1.092548 * d.x * d.y;
    b[5] = 1.092548 * d.y * d.z;
    b[6] = 0.315392 * (3.0 * d.z * d.z - 1.0);
    b[7] = 1.092548 * d.x * d.z;
    b[8] = 0.546274 * (d.x * d.x - d.y * d.y);
}
