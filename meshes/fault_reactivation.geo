// A fault near an injection well (scenes/fault_reactivation.toml), plane
// strain: the square [-2000, 2000]^2 m with a straight fault of 1200 m
// through its centre, dipping 60 degrees (its tips at +-(300, 519.6) m,
// inside the body), the physical curve "fault" embedded in the surface
// "rock"; the well is a point source 250 m left of the fault's centre.
// Sizes: 10 m along the fault and around the well, growing by 0.2 m per
// metre to 200 m. Sides "left", "right", "bottom", "top".
SetFactory("Built-in");
W = 2000;
F = 600;                  // half-length of the fault (m)
dip = 60 * Pi / 180;
Point(1) = {-W, -W, 0}; Point(2) = {W, -W, 0}; Point(3) = {W, W, 0}; Point(4) = {-W, W, 0};
Point(5) = {-F * Cos(dip), -F * Sin(dip), 0}; Point(6) = {F * Cos(dip), F * Sin(dip), 0};
Point(7) = {-250, 0, 0};  // the well
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1}; Line(5) = {5, 6};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Curve{5} In Surface{1};
Point{7} In Surface{1};
Physical Curve("bottom") = {1}; Physical Curve("right") = {2}; Physical Curve("top") = {3};
Physical Curve("left") = {4}; Physical Curve("fault") = {5}; Physical Surface("rock") = {1};
Field[1] = Distance;
Field[1].CurvesList = {5};
Field[1].PointsList = {7};
Field[1].NumPointsPerCurve = 400;
Field[2] = MathEval;
Field[2].F = "Min(10 + 0.2 * F1, 200)";
Background Field = 2;
Mesh.CharacteristicLengthExtendFromBoundary = 0;
Mesh.CharacteristicLengthFromPoints = 0;
