// Half of the cross-section of a cylinder of radius 1 (x >= 0, below its
// centre), for Hertz line contact (scenes/hertz.toml): the arc touches the
// rigid flat y = 0 at the origin. Refined towards the contact.
SetFactory("Built-in");
Point(1) = {0, 0, 0};       // lowest point, first contact
Point(2) = {0, 1, 0};       // centre
Point(3) = {1, 1, 0};
Line(1) = {2, 1};           // symmetry axis x = 0
Circle(2) = {1, 2, 3};      // the arc, contact boundary
Line(3) = {3, 2};           // the loaded cut through the centre
Curve Loop(1) = {1, 2, 3};
Plane Surface(1) = {1};
Physical Curve("symmetry") = {1};
Physical Curve("arc") = {2};
Physical Curve("top") = {3};
Physical Surface("cylinder") = {1};
// Element size 0.004 within 0.15 of the contact point, 0.08 far away.
Field[1] = Distance;
Field[1].PointsList = {1};
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = 0.004;
Field[2].SizeMax = 0.08;
Field[2].DistMin = 0.15;
Field[2].DistMax = 0.5;
Background Field = 2;
Mesh.CharacteristicLengthExtendFromBoundary = 0;
Mesh.CharacteristicLengthFromPoints = 0;
