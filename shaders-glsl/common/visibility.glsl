// A vertex's visibility: its transfer's DC term (visibility-weighted cosine,
// light/occlusion.rs) relative to an unoccluded vertex's, Â0·Y00 = π·0.282095
// (Ramamoorthi & Hanrahan 2001: Â0 = π, Y00 = 1/(2√π)). 1 under open sky.
float open_sky(float t0) {
    return t0 / (3.14159265358979 * 0.282095);
}
