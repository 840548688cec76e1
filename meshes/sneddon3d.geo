// A penny-shaped crack under a fluid pressure, the 3D verification of a split
// fault (closed form: penny_opening in cpp/diagnostics/closed_form.h): a disc
// of radius a = 1 m in the plane z = 0, centred in the cube [-25, 25]^3 m
// (25 radii each way: the finite body changes the opening by O((a/25)^3),
// far below the mesh's error). The disc is the physical surface "crack",
// embedded in the volume "rock": its nodes are shared by the cells on both
// sides until the split duplicates them (its rim stays shared).
// Sizes: 0.04 m (a/25) on the disc, growing to 0.1 m at 0.5 m from it, where
// the opening is decided; 0.012 m within 0.03 m of the rim, where the
// square-root opening is hardest to follow with P1, growing to the disc's
// 0.04 m at 0.15 m; beyond 0.5 m growing by 0.2 m per metre to 5 m at the
// faces. About 57k nodes. Measured with a P1 split of this mesh (E = 10 GPa,
// nu = 0.25, faces of the cube held): the opening 2.7 % below the closed
// form at the centre, 3.1 % in l2 over r <= 0.8 a (4.0 % and 4.7 % with
// 0.045 m growing to 0.15 m, 33k nodes; 7 % with a/12.5, 9k nodes).
SetFactory("OpenCASCADE");
a = 1;    // radius of the crack (m)
L = 25;   // half-side of the cube (m)
Box(1) = {-L, -L, -L, 2 * L, 2 * L, 2 * L};
Disk(100) = {0, 0, 0, a};
// The disc becomes an internal face of the cube, meshed conformingly.
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
// Distance to the disc: its radial excess (outside the rim) and height.
Field[1] = MathEval;
Field[1].F = Sprintf("Sqrt(Max(Sqrt(x^2 + y^2) - %g, 0)^2 + z^2)", a);
Field[2] = Threshold;   // near the disc, where its opening is decided
Field[2].InField = 1;
Field[2].SizeMin = 0.04;
Field[2].SizeMax = 0.1;
Field[2].DistMin = 0;
Field[2].DistMax = 0.5;
Field[2].StopAtDistMax = 1;
Field[3] = Threshold;   // the far field
Field[3].InField = 1;
Field[3].SizeMin = 0.1;
Field[3].SizeMax = 5;
Field[3].DistMin = 0.5;
Field[3].DistMax = 25;
// Distance to the rim.
Field[4] = MathEval;
Field[4].F = Sprintf("Sqrt((Sqrt(x^2 + y^2) - %g)^2 + z^2)", a);
Field[5] = Threshold;
Field[5].InField = 4;
Field[5].SizeMin = 0.012;
Field[5].SizeMax = 0.04;
Field[5].DistMin = 0.03;
Field[5].DistMax = 0.15;
Field[5].StopAtDistMax = 1; // beyond it the disc's size
Field[6] = Min;
Field[6].FieldsList = {2, 3, 5};
Background Field = 6;
Mesh.CharacteristicLengthExtendFromBoundary = 0;
Mesh.CharacteristicLengthFromPoints = 0;
Mesh.CharacteristicLengthFromCurvature = 0;
