// Vertical cross-section (plane strain) through a height-contained hydraulic
// fracture, by symmetry a quarter: x along the fracture height from its
// centre (x = 0), y normal to the fracture plane (y = 0). The fracture face
// is 0 <= x <= 15 m on y = 0 (scenes/fracture.toml); beyond its tip the
// plane y = 0 is the symmetry plane of intact rock. 60 m x 60 m; cells of
// 0.5 m along the fracture face, growing to 8 m in the far field.
SetFactory("Built-in");
a = 15;    // half-height of the fracture (m)
L = 60;    // extent of the formation modelled (m)
Point(1) = {0, 0, 0};
Point(2) = {a, 0, 0};     // the tip
Point(3) = {L, 0, 0};
Point(4) = {L, L, 0};
Point(5) = {0, L, 0};
Line(1) = {1, 2};         // fracture face
Line(2) = {2, 3};         // symmetry plane beyond the tip
Line(3) = {3, 4};         // far field, along the height
Line(4) = {4, 5};         // far field, normal to the fracture
Line(5) = {5, 1};         // symmetry plane of the fracture height (x = 0)
Curve Loop(1) = {1, 2, 3, 4, 5};
Plane Surface(1) = {1};
Physical Curve("fracture") = {1};
Physical Curve("intact") = {2};
Physical Curve("right") = {3};
Physical Curve("top") = {4};
Physical Curve("centre") = {5};
Physical Surface("formation") = {1};
Field[1] = Distance;
Field[1].CurvesList = {1};
Field[1].NumPointsPerCurve = 200;
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = 0.5;
Field[2].SizeMax = 8;
Field[2].DistMin = 1;
Field[2].DistMax = 40;
Background Field = 2;
Mesh.CharacteristicLengthExtendFromBoundary = 0;
Mesh.CharacteristicLengthFromPoints = 0;
