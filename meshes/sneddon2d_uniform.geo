// meshes/sneddon2d_near.geo's crack and square (half-length 1 m at 30
// degrees, a square of 2 half-lengths each way) meshed uniformly, cells of
// size 0.1 m: the mesh a user draws without grading it. The project
// grades it toward the tips (fault.crack.tip_size, scenes/sneddon_tips.toml).
SetFactory("Built-in");
a = 1;
L = 2;
theta = Pi / 6;
h = 0.1;
Point(1) = {-L, -L, 0, h};
Point(2) = {L, -L, 0, h};
Point(3) = {L, L, 0, h};
Point(4) = {-L, L, 0, h};
Point(5) = {-a * Cos(theta), -a * Sin(theta), 0, h}; // the tips
Point(6) = {a * Cos(theta), a * Sin(theta), 0, h};
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
