// The default scene's cantilever (10 m x 1 m) as a gmsh geometry, refined
// towards the free end where the contact front moves.
SetFactory("Built-in");
Point(1) = {0, 0, 0, 0.3};
Point(2) = {10, 0, 0, 0.1};
Point(3) = {10, 1, 0, 0.1};
Point(4) = {0, 1, 0, 0.3};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Physical Curve("bottom") = {1};
Physical Curve("right") = {2};
Physical Curve("top") = {3};
Physical Curve("left") = {4};
Physical Surface("block") = {1};
