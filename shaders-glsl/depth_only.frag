#version 460
// The depth pre-pass of the skin pass (skin/shade.rs): depth only, no colour, so
// the shading that follows runs once per pixel instead of once per overdrawn
// fragment.
void main() {}
