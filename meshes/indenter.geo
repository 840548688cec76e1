// Half of an elastic block (x in [0, 4], y in [-4, 0]) for a rigid cylinder
// of radius 1 indenting its top (scenes/indenter.toml): the cylinder's
// lowest point touches the top at the origin. Refined towards the contact.
SetFactory("Built-in");
Point(1) = {0, 0, 0};
Point(2) = {4, 0, 0};
Point(3) = {4, -4, 0};
Point(4) = {0, -4, 0};
Line(1) = {1, 2};           // the top, contact boundary
Line(2) = {2, 3};           // the free side
Line(3) = {3, 4};           // the base, pushed up
Line(4) = {4, 1};           // symmetry axis x = 0
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Physical Curve("top") = {1};
Physical Curve("side") = {2};
Physical Curve("base") = {3};
Physical Curve("symmetry") = {4};
Physical Surface("block") = {1};
// Element size 0.002 within 0.15 of the first contact, 0.25 far away.
Field[1] = Distance;
Field[1].PointsList = {1};
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = 0.002;
Field[2].SizeMax = 0.25;
Field[2].DistMin = 0.15;
Field[2].DistMax = 1.5;
Background Field = 2;
Mesh.CharacteristicLengthExtendFromBoundary = 0;
Mesh.CharacteristicLengthFromPoints = 0;
