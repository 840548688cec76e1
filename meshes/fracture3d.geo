// A quarter of a height-contained hydraulic fracture in 3D (scenes/
// fracture3d.toml): x along the fracture height from its centre, y normal to
// the fracture plane (y = 0), z along its length from the wellbore. The
// fracture face is the quarter ellipse x^2/15^2 + z^2/30^2 <= 1 of y = 0;
// the rest of y = 0 is the symmetry plane of intact rock. 60 m cube; cells
// of 1.5 m along the fracture face, growing to 12 m in the far field.
SetFactory("OpenCASCADE");
a = 15;   // half-height (m)
b = 30;   // half-length (m)
L = 60;
Box(1) = {0, 0, 0, L, L, L};
// The quarter ellipse, built in z = 0 (semi-axes b along x, a along y) and
// turned into y = 0 (b along z, a along x).
Disk(100) = {0, 0, 0, b, a};
Rectangle(101) = {0, 0, 0, b, a};
quarter() = BooleanIntersection{ Surface{100}; Delete; }{ Surface{101}; Delete; };
Rotate {{1, 0, 0}, {0, 0, 0}, -Pi/2} { Surface{quarter()}; }
Rotate {{0, 1, 0}, {0, 0, 0}, -Pi/2} { Surface{quarter()}; }
BooleanFragments{ Volume{1}; Delete; }{ Surface{quarter()}; Delete; }
e = 1e-6;
fracture() = Surface In BoundingBox{-e, -e, -e, a + e, e, b + e};
bottom() = Surface In BoundingBox{-e, -e, -e, L + e, e, L + e};
Physical Surface("fracture") = {fracture()};
Physical Surface("intact") = {bottom()};
Physical Surface("intact") -= {fracture()};
Physical Surface("centre") = {Surface In BoundingBox{-e, -e, -e, e, L + e, L + e}};
Physical Surface("right") = {Surface In BoundingBox{L - e, -e, -e, L + e, L + e, L + e}};
Physical Surface("top") = {Surface In BoundingBox{-e, L - e, -e, L + e, L + e, L + e}};
Physical Surface("wellbore") = {Surface In BoundingBox{-e, -e, -e, L + e, L + e, e}};
Physical Surface("far") = {Surface In BoundingBox{-e, -e, L - e, L + e, L + e, L + e}};
Physical Volume("formation") = {Volume{:}};
Field[1] = Distance;
Field[1].SurfacesList = {fracture()};
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = 1.5;
Field[2].SizeMax = 12;
Field[2].DistMin = 1;
Field[2].DistMax = 40;
Background Field = 2;
Mesh.CharacteristicLengthExtendFromBoundary = 0;
Mesh.CharacteristicLengthFromPoints = 0;
Mesh.CharacteristicLengthFromCurvature = 0;
