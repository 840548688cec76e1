// A wedge (2 m wide, 30 degree flanks, apex at the origin) under a 1 m
// block, for scenes/groove.toml: its two flanks rest on a rigid V-groove
// of the same angle, each flank a contact boundary with its own normal.
SetFactory("Built-in");
t = Tan(Pi/6);
Point(1) = {0, 0, 0, 0.02};      // the apex: a node on both flanks
Point(2) = {1, t, 0, 0.05};
Point(3) = {1, t + 1, 0, 0.05};
Point(4) = {-1, t + 1, 0, 0.05};
Point(5) = {-1, t, 0, 0.05};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 5};
Line(5) = {5, 1};
Curve Loop(1) = {1, 2, 3, 4, 5};
Plane Surface(1) = {1};
Physical Curve("right_flank") = {1};
Physical Curve("right") = {2};
Physical Curve("top") = {3};
Physical Curve("left") = {4};
Physical Curve("left_flank") = {5};
Physical Surface("wedge") = {1};
