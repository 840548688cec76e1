// A square of side 2000 m around a well at the origin (tests/test_theis.py):
// large enough that the pressure front of the test times (radius about 40
// m) and the displacement around it do not feel the outer boundary. The
// well is a node of the mesh; the elements grow from 0.5 m at the well to
// 50 m at the boundary.
SetFactory("Built-in");
L = 1000;
Point(1) = {-L, -L, 0};
Point(2) = {L, -L, 0};
Point(3) = {L, L, 0};
Point(4) = {-L, L, 0};
Point(5) = {0, 0, 0};       // the well
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Point{5} In Surface{1};
Physical Curve("outer") = {1, 2, 3, 4};
Physical Surface("formation") = {1};
// Element size 0.5 m at the well, growing by 0.05 per metre (1.5 m at 20 m).
Field[1] = Distance;
Field[1].PointsList = {5};
Field[2] = MathEval;
Field[2].F = "0.5 + 0.05 * F1";
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
