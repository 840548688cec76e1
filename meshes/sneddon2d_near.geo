// meshes/sneddon2d.geo's crack (half-length 1 m, at 30 degrees) in a square
// of 2 half-lengths each way, whose boundary takes the infinite plane's
// displacement (scenes/sneddon_near.toml): no finite-body correction to
// make, so a square 25 times smaller than the clamped one will do.
L = 2;
Include "sneddon2d.geo";
