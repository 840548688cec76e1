// Sneddon's pressurised crack in plane strain, the verification of a split
// fault under a fluid pressure (closed form: sneddon_opening in
// cpp/diagnostics/closed_form.h): a straight crack of half-length a = 1 m
// centred at the origin and inclined at 30 degrees to the x axis, embedded
// in the square [-50, 50]^2 m (50 half-lengths each way, so the finite body
// changes the opening by O((a/50)^2), below 0.1 %). The crack is the
// physical curve "crack", embedded in the surface "rock": its nodes are
// shared by the cells on both sides until the split duplicates them (the
// tips stay shared, where the opening is zero anyway).
// Sizes: 0.01 m (a/100) along the crack, 0.0025 m (a/400) within 0.02 m of
// either tip, where the square-root opening is hardest to follow with P1;
// growing by 0.1 m per metre from the crack to 5 m at the sides. About 22k
// nodes.
SetFactory("Built-in");
a = 1;          // half-length of the crack (m)
If (!Exists(L))  // meshes/phan2d.geo sets L and theta, then includes this file
  L = 50;        // half-side of the square (m)
EndIf
If (!Exists(theta))
  theta = Pi / 6; // inclination of the crack to the x axis
EndIf
If (!Exists(scale)) // meshes/phan2d_coarse.geo: the sizes near the crack times scale
  scale = 1;
EndIf
Point(1) = {-L, -L, 0};
Point(2) = {L, -L, 0};
Point(3) = {L, L, 0};
Point(4) = {-L, L, 0};
Point(5) = {-a * Cos(theta), -a * Sin(theta), 0}; // the tips
Point(6) = {a * Cos(theta), a * Sin(theta), 0};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Line(5) = {5, 6}; // the crack
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Curve{5} In Surface{1};
Physical Curve("bottom") = {1};
Physical Curve("right") = {2};
Physical Curve("top") = {3};
Physical Curve("left") = {4};
Physical Curve("crack") = {5};
Physical Surface("rock") = {1};
Field[1] = Distance;
Field[1].CurvesList = {5};
Field[1].NumPointsPerCurve = 1000; // 2 mm apart: the distance is exact to well below the finest cell
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = 0.01 * scale;
Field[2].SizeMax = 5;
Field[2].DistMin = 0.02;
Field[2].DistMax = 50;
Field[3] = Distance;
Field[3].PointsList = {5, 6};
Field[4] = Threshold;
Field[4].InField = 3;
Field[4].SizeMin = 0.004 * scale;
Field[4].SizeMax = 5;
Field[4].DistMin = 0.02;
Field[4].DistMax = 50;
Field[5] = Min;
Field[5].FieldsList = {2, 4};
Background Field = 5;
Mesh.CharacteristicLengthExtendFromBoundary = 0;
Mesh.CharacteristicLengthFromPoints = 0;
