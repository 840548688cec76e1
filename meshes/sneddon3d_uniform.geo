// meshes/sneddon3d.geo's penny-shaped crack (a disc of radius 1 m in the
// plane z = 0, in the cube [-25, 25]^3 m) with no size fields of its own:
// cells of at most 5 m, the mesh a user draws without grading it. The
// project grades it toward the crack's rim (fault.crack.tip_size and
// tip_grading: scenes/penny.toml). Meshed by HXT (Mesh.Algorithm3D = 10):
// 4 s for 6.7e5 cells where gmsh 4.8's default Delaunay takes 66-79 s; HXT's
// mesh differs a little from run to run (a few 1e-4 of the cells).
SetFactory("OpenCASCADE");
a = 1;    // radius of the crack (m)
L = 25;   // half-side of the cube (m)
Box(1) = {-L, -L, -L, 2 * L, 2 * L, 2 * L};
Disk(100) = {0, 0, 0, a};
BooleanFragments{ Volume{1}; Delete; }{ Surface{100}; Delete; }
e = 1e-6;
Physical Surface("crack") = {Surface In BoundingBox{-a - e, -a - e, -e, a + e, a + e, e}};
Physical Surface("left") = {Surface In BoundingBox{-L - e, -L - e, -L - e, -L + e, L + e, L + e}};
Physical Surface("right") = {Surface In BoundingBox{L - e, -L - e, -L - e, L + e, L + e, L + e}};
Physical Surface("front") = {Surface In BoundingBox{-L - e, -L - e, -L - e, L + e, -L + e, L + e}};
Physical Surface("back") = {Surface In BoundingBox{-L - e, L - e, -L - e, L + e, L + e, L + e}};
Physical Surface("bottom") = {Surface In BoundingBox{-L - e, -L - e, -L - e, L + e, L + e, -L + e}};
Physical Surface("top") = {Surface In BoundingBox{-L - e, -L - e, L - e, L + e, L + e, L + e}};
Physical Volume("rock") = {Volume{:}};
Mesh.CharacteristicLengthMax = 5;
Mesh.Algorithm3D = 10;
