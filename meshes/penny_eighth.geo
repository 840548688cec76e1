// An eighth of Sneddon's penny-shaped crack (scenes/penny_eighth.toml): the
// cube [0, 25]^3 m, the crack's quarter disc r <= a = 1 m on z = 0 (a
// contact boundary against the crack's plane of symmetry), the rest of z = 0
// the symmetry plane of intact rock, x = 0 and y = 0 planes of symmetry.
// Cells of 0.02 m at the rim, growing by 0.1 m per metre away from it, at
// most 5 m (mesh.size_factor scales them all). Meshed by HXT, as
// sneddon3d_uniform.geo (its mesh differs a little from run to run).
SetFactory("OpenCASCADE");
a = 1;    // radius of the crack (m)
L = 25;   // side of the cube (m)
Box(1) = {0, 0, 0, L, L, L};
Disk(100) = {0, 0, 0, a};
Rectangle(101) = {0, 0, 0, a, a};
quarter() = BooleanIntersection{ Surface{100}; Delete; }{ Surface{101}; Delete; };
BooleanFragments{ Volume{1}; Delete; }{ Surface{quarter()}; Delete; }
e = 1e-6;
crack() = Surface In BoundingBox{-e, -e, -e, a + e, a + e, e};
Physical Surface("crack") = {crack()};
Physical Surface("intact") = {Surface In BoundingBox{-e, -e, -e, L + e, L + e, e}};
Physical Surface("intact") -= {crack()};
Physical Surface("xsymmetry") = {Surface In BoundingBox{-e, -e, -e, e, L + e, L + e}};
Physical Surface("ysymmetry") = {Surface In BoundingBox{-e, -e, -e, L + e, e, L + e}};
Physical Surface("outer") = {Surface In BoundingBox{L - e, -e, -e, L + e, L + e, L + e},
                             Surface In BoundingBox{-e, L - e, -e, L + e, L + e, L + e},
                             Surface In BoundingBox{-e, -e, L - e, L + e, L + e, L + e}};
Physical Volume("rock") = {Volume{:}};
rim() = Curve In BoundingBox{-e, -e, -e, a + e, a + e, e};
rim() -= {Curve In BoundingBox{-e, -e, -e, e, a + e, e}};
rim() -= {Curve In BoundingBox{-e, -e, -e, a + e, e, e}};
Field[1] = Distance;
Field[1].CurvesList = {rim()};
Field[1].NumPointsPerCurve = 1000;
Field[2] = MathEval;
Field[2].F = "Min(0.02 + 0.1 * F1, 5)";
Background Field = 2;
Mesh.CharacteristicLengthExtendFromBoundary = 0;
Mesh.CharacteristicLengthFromPoints = 0;
Mesh.Algorithm3D = 10;
