// The displaced fault of Jansen & Meulenbroek (2022), plane strain: a vertical
// fault at x = 0 offsets a laterally unbounded reservoir, which spans
// -b <= y <= a left of the fault (x < 0) and -a <= y <= b right of it
// (x > 0), a = 75 m, b = 150 m: thickness a + b = 225 m, throw b - a = 75 m.
// Depleting the reservoir makes a frictionless fault slip by the trapezoid of
// jansen_meulenbroek_slip (cpp/diagnostics/closed_form.h), nonzero only on
// |y| < b. That slip is exact for any fault containing -b <= y <= b (it
// leaves no shear traction anywhere on the line x = 0), so the fault, the
// physical curve "fault", runs from y = -1000 m to 1000 m with its tips
// inside the body, where the slip is zero. The domain [-8000, 8000]^2 m
// (about 35 reservoir thicknesses each way) stands for the unbounded plane:
// far from the fault the reservoir is in uniaxial strain, which rollers on
// "left" and "right" keep. Measured with a P1 split of this mesh, the fault
// tied normally and free tangentially, rollers on the sides, the bottom
// held vertically, the top free (E = 14.95 GPa, nu = 0.15, alpha = 0.9,
// dp = -25 MPa): the slip's plateau 0.30 % below the closed form, 0.4 % in
// l2 along the fault; in [-2000, 2000]^2 the boundaries took 1.7 % and
// 3.7 % (a slip of -2.5 mm along the whole fault), in [-4000, 4000]^2
// 0.6 % and 1.1 %.
// Surfaces "reservoir_left", "reservoir_right" and "rock" (above and below);
// sides "left", "right", "bottom", "top".
// Sizes: 1 m at the four reservoir corners on the fault (y = -b, -a, a, b),
// where the fault's shear load is singular and the slip has its kinks,
// growing by 0.1 m per metre; 4 m along the fault where it meets the
// reservoir (|y| <= b), growing by 0.2 m per metre away from it; 25 m along
// the reservoir's top and bottom, growing by 0.25 m per metre; 400 m in the
// far field. About 18k nodes.
SetFactory("Built-in");
a = 75;     // the two reservoirs face each other across the fault on |y| <= a (m)
b = 150;    // and each reaches |y| = b on its own side (m)
If (!Exists(W))      // half-width and half-height of the domain (m)
  W = 8000;
EndIf
If (!Exists(scale))  // meshes/fault_depletion_coarse.geo: every size times scale
  scale = 1;
EndIf
F = 1000;   // the fault's tips at y = -F and F (m)
Point(1) = {-W, -W, 0};   Point(2) = {W, -W, 0};
Point(3) = {W, W, 0};     Point(4) = {-W, W, 0};
Point(5) = {-W, -b, 0};   Point(6) = {-W, a, 0};    // the left reservoir's ends
Point(7) = {W, -a, 0};    Point(8) = {W, b, 0};     // the right reservoir's ends
Point(9) = {0, -F, 0};    Point(10) = {0, -b, 0};   // along the fault, upwards
Point(11) = {0, -a, 0};   Point(12) = {0, a, 0};
Point(13) = {0, b, 0};    Point(14) = {0, F, 0};
// The fault, bottom to top: in the rock, between the left reservoir and
// rock, between the two reservoirs, between rock and the right reservoir,
// in the rock.
Line(1) = {9, 10};
Line(2) = {10, 11};
Line(3) = {11, 12};
Line(4) = {12, 13};
Line(5) = {13, 14};
// The reservoirs' tops and bottoms.
Line(6) = {5, 10};   // left bottom
Line(7) = {6, 12};   // left top
Line(8) = {11, 7};   // right bottom
Line(9) = {13, 8};   // right top
// The sides, bottom to top.
Line(10) = {1, 2};   // bottom
Line(11) = {2, 7};   Line(12) = {7, 8};   Line(13) = {8, 3};   // right
Line(14) = {3, 4};   // top
Line(15) = {4, 6};   Line(16) = {6, 5};   Line(17) = {5, 1};   // left
Curve Loop(1) = {6, 2, 3, -7, 16};             // left reservoir
Curve Loop(2) = {8, 12, -9, -4, -3};           // right reservoir
Curve Loop(3) = {7, 4, 9, 13, 14, 15};         // rock above
Curve Loop(4) = {10, 11, -8, -2, -6, 17};      // rock below
Plane Surface(1) = {1};
Plane Surface(2) = {2};
Plane Surface(3) = {3};
Plane Surface(4) = {4};
// The fault's parts beyond the reservoir are inside the rock.
Curve{5} In Surface{3};
Curve{1} In Surface{4};
Physical Curve("fault") = {1, 2, 3, 4, 5};
Physical Curve("bottom") = {10};
Physical Curve("right") = {11, 12, 13};
Physical Curve("top") = {14};
Physical Curve("left") = {15, 16, 17};
Physical Surface("reservoir_left") = {1};
Physical Surface("reservoir_right") = {2};
Physical Surface("rock") = {3, 4};
Field[1] = Distance;
Field[1].PointsList = {10, 11, 12, 13};
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = 1 * scale;
Field[2].SizeMax = 400 * scale;
Field[2].DistMin = 1;
Field[2].DistMax = 4000;
Field[3] = Distance;
Field[3].CurvesList = {2, 3, 4};
Field[3].NumPointsPerCurve = 300;
Field[4] = Threshold;
Field[4].InField = 3;
Field[4].SizeMin = 4 * scale;
Field[4].SizeMax = 400 * scale;
Field[4].DistMin = 0;
Field[4].DistMax = 1980;
Field[5] = Distance;
Field[5].CurvesList = {6, 7, 8, 9};
Field[5].NumPointsPerCurve = 400;
Field[6] = Threshold;
Field[6].InField = 5;
Field[6].SizeMin = 25 * scale;
Field[6].SizeMax = 400 * scale;
Field[6].DistMin = 0;
Field[6].DistMax = 1500;
Field[7] = Min;
Field[7].FieldsList = {2, 4, 6};
Background Field = 7;
Mesh.CharacteristicLengthExtendFromBoundary = 0;
Mesh.CharacteristicLengthFromPoints = 0;
