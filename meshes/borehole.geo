// Half of the section of a horizontal well (x >= 0; symmetry on x = 0) for
// scenes/borehole.toml: the formation between the wall of the 8.5 in hole
// (radius 0.108 m) and a far boundary at 3 m. Refined towards the wall.
SetFactory("Built-in");
rw = 0.108;
ro = 3.0;
Point(1) = {0, 0, 0};
Point(2) = {0, -rw, 0, 0.004};
Point(3) = {rw, 0, 0, 0.004};
Point(4) = {0, rw, 0, 0.004};
Point(5) = {0, -ro, 0, 0.3};
Point(6) = {ro, 0, 0, 0.3};
Point(7) = {0, ro, 0, 0.3};
Circle(1) = {2, 1, 3};      // the wall, low side
Circle(2) = {3, 1, 4};      // the wall, high side
Line(3) = {4, 7};           // symmetry above the well
Circle(4) = {7, 1, 6};
Circle(5) = {6, 1, 5};      // the far boundary
Line(6) = {5, 2};           // symmetry below the well
Curve Loop(1) = {1, 2, 3, 4, 5, 6};
Plane Surface(1) = {1};
Physical Curve("wall") = {1, 2};
Physical Curve("far") = {4, 5};
Physical Curve("symmetry") = {3, 6};
Physical Surface("formation") = {1};
// Element size 0.004 at the wall, growing to 0.3 at 1.5 m.
Field[1] = MathEval;
Field[1].F = "Sqrt(x^2 + y^2) - 0.108";
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = 0.004;
Field[2].SizeMax = 0.3;
Field[2].DistMin = 0.02;
Field[2].DistMax = 1.5;
Background Field = 2;
Mesh.CharacteristicLengthExtendFromBoundary = 0;
Mesh.CharacteristicLengthFromPoints = 0;
