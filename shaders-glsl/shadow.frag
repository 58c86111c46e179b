#version 460
// Depth only: the shadow pass writes no colour.
void main() {}
