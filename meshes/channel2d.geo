// A 10 m x 2 m channel with a conduit fault along its axis (the physical
// curve "crack", y = 0, from the inlet "left" to the outlet "right"; its
// ends on the boundary): the cubic law's closed forms, steady (linear) and
// transient (erfc), in tests/test_conduit_fault.py and
// studies/conduit_transient.toml. Cells of h, set from outside with
// `h = ...; Include "channel2d.geo";` or by the tests' replacement.
SetFactory("Built-in");
L = 10; H = 1; If (!Exists(h)) h = 0.25; EndIf
Point(1) = {0, -H, 0, h}; Point(2) = {L, -H, 0, h}; Point(3) = {L, 0, 0, h}; Point(4) = {L, H, 0, h};
Point(5) = {0, H, 0, h}; Point(6) = {0, 0, 0, h};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 5}; Line(5) = {5, 6}; Line(6) = {6, 1};
Line(7) = {6, 3};
Curve Loop(1) = {1, 2, 3, 4, 5, 6}; Plane Surface(1) = {1};
Line{7} In Surface{1};
Physical Curve("bottom") = {1}; Physical Curve("right") = {2, 3}; Physical Curve("top") = {4};
Physical Curve("left") = {5, 6}; Physical Curve("crack") = {7}; Physical Surface("rock") = {1};
