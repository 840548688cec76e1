// Vertical section (plane strain) across a horizontal CO2 injector at the
// base of a caprock, by symmetry a half: x from the well's vertical plane
// (x = 0) to 1500 m, y the elevation (m, negative down). Layers: the base
// (y < -1820), the reservoir (20 m), the caprock (y > -1800), and in the
// caprock above the well a vertical fracture zone (x < 5 m, 150 m tall)
// whose plane of symmetry x = 0 is the "fracture" face. Cells of 1 m at the
// fracture zone and the well, growing to 100 m in the far field.
SetFactory("Built-in");
W = 1500;   // half-width modelled (m)
w = 5;      // half-width of the fracture zone (m)
yb = -2100; yr = -1820; yc = -1800; yf = -1650; yt = -1500;
Point(1) = {0, yb, 0};   Point(2) = {W, yb, 0};
Point(3) = {W, yr, 0};   Point(4) = {0, yr, 0};
Point(5) = {W, yc, 0};   Point(6) = {w, yc, 0};   Point(7) = {0, yc, 0};
Point(8) = {w, yf, 0};   Point(9) = {0, yf, 0};
Point(10) = {W, yt, 0};  Point(11) = {0, yt, 0};
Line(1) = {1, 2};   Line(2) = {2, 3};   Line(3) = {3, 4};   Line(4) = {4, 1};    // base
Line(5) = {3, 5};   Line(6) = {5, 6};   Line(7) = {6, 7};   Line(8) = {7, 4};    // reservoir
Line(9) = {6, 8};   Line(10) = {8, 9};  Line(11) = {9, 7};                       // fracture zone
Line(12) = {5, 10}; Line(13) = {10, 11}; Line(14) = {11, 9};                     // caprock
Curve Loop(1) = {1, 2, 3, 4};
Curve Loop(2) = {-3, 5, 6, 7, 8};
Curve Loop(3) = {-7, 9, 10, 11};
Curve Loop(4) = {-6, 12, 13, 14, -10, -9};
Plane Surface(1) = {1};
Plane Surface(2) = {2};
Plane Surface(3) = {3};
Plane Surface(4) = {4};
Physical Curve("bottom") = {1};
Physical Curve("far") = {2, 5, 12};
Physical Curve("top") = {13};
Physical Curve("fracture") = {11};
Physical Curve("symmetry") = {4, 8, 14};
Physical Surface("base") = {1};
Physical Surface("reservoir") = {2};
Physical Surface("fracture_zone") = {3};
Physical Surface("caprock") = {4};
Field[1] = Distance;
Field[1].CurvesList = {8, 11};
Field[1].NumPointsPerCurve = 200;
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = 1;
Field[2].SizeMax = 100;
Field[2].DistMin = 5;
Field[2].DistMax = 800;
Field[3] = Box;   // the reservoir: at most 5 m across its 20 m
Field[3].VIn = 5;
Field[3].VOut = 100;
Field[3].XMin = 0; Field[3].XMax = W; Field[3].YMin = yr; Field[3].YMax = yc;
Field[4] = Min;
Field[4].FieldsList = {2, 3};
Background Field = 4;
Mesh.CharacteristicLengthExtendFromBoundary = 0;
Mesh.CharacteristicLengthFromPoints = 0;
