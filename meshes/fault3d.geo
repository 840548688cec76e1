// A 3D showcase of a fault inside the body: a block of 2 km x 2 km x 1 km
// (x, y in [-1000, 1000] m, z in [-1000, 0] m, z up) of three layers, the
// "underburden" (z < -600), a 100 m "reservoir" (-600 < z < -500) and the
// "overburden" (z > -500), cut by a planar fault striking along y and
// dipping 60 degrees towards +x: a 400 m (down dip) by 1000 m (along strike)
// rectangle centred at (0, 0, -550) m, its four edges inside the body, so it
// crosses the reservoir and ends in the rock above and below. The fault, the
// physical surface "fault", is an internal face of the three layers (each
// holds its part): its nodes are shared by the cells on both sides until the
// split duplicates them (its edges stay shared). Outer faces "left", "right"
// (x), "front", "back" (y), each made of the three layers' faces, "bottom"
// and "top" (z).
// Sizes: 25 m on the fault, growing by 0.25 m per metre away from it; 20 m
// in the reservoir within 200 m of the fault's vertical plane (five cells
// across the reservoir where the fault crosses it), growing to 200 m over
// 600 m; 200 m in the far field. About 21k nodes.
SetFactory("OpenCASCADE");
If (!Exists(h_fault))  // meshes/injection_fault3d.geo sets coarser sizes, then includes this file
  h_fault = 25;        // on the fault (m)
  h_reservoir = 20;    // in the reservoir near the fault (m)
  h_far = 200;         // in the far field (m)
EndIf
W = 1000;                    // half-width of the block (m)
H = 1000;                    // depth of the block (m)
zr = -600; zo = -500;        // the reservoir's bottom and top (m)
width = 400; length = 1000;  // the fault down dip and along strike (m)
dip = Pi / 3;
Box(1) = {-W, -W, -H, 2 * W, 2 * W, zr + H};
Box(2) = {-W, -W, zr, 2 * W, 2 * W, zo - zr};
Box(3) = {-W, -W, zo, 2 * W, 2 * W, -zo};
// Built flat (x down dip, y along strike) about the origin, dipped by turning
// about the y axis (which takes +x down), then moved to the reservoir.
Rectangle(100) = {-width / 2, -length / 2, 0, width, length};
Rotate {{0, 1, 0}, {0, 0, 0}, dip} { Surface{100}; }
Translate {0, 0, (zr + zo) / 2} { Surface{100}; }
BooleanFragments{ Volume{1, 2, 3}; Delete; }{ Surface{100}; Delete; }
e = 1e-3;
hx = width / 2 * Cos(dip) + e; hz = width / 2 * Sin(dip) + e; zc = (zr + zo) / 2;
Physical Surface("fault") = {Surface In BoundingBox{-hx, -length / 2 - e, zc - hz, hx, length / 2 + e, zc + hz}};
Physical Surface("left") = {Surface In BoundingBox{-W - e, -W - e, -H - e, -W + e, W + e, e}};
Physical Surface("right") = {Surface In BoundingBox{W - e, -W - e, -H - e, W + e, W + e, e}};
Physical Surface("front") = {Surface In BoundingBox{-W - e, -W - e, -H - e, W + e, -W + e, e}};
Physical Surface("back") = {Surface In BoundingBox{-W - e, W - e, -H - e, W + e, W + e, e}};
Physical Surface("bottom") = {Surface In BoundingBox{-W - e, -W - e, -H - e, W + e, W + e, -H + e}};
Physical Surface("top") = {Surface In BoundingBox{-W - e, -W - e, -e, W + e, W + e, e}};
Physical Volume("underburden") = {Volume In BoundingBox{-W - e, -W - e, -H - e, W + e, W + e, zr + e}};
Physical Volume("reservoir") = {Volume In BoundingBox{-W - e, -W - e, zr - e, W + e, W + e, zo + e}};
Physical Volume("overburden") = {Volume In BoundingBox{-W - e, -W - e, zo - e, W + e, W + e, e}};
// Distance to the fault rectangle: in its frame (s down dip, t along strike,
// n normal), the excess of s and t beyond its edges and n.
Field[1] = MathEval;
Field[1].F = Sprintf(StrCat("Sqrt(Max(Fabs(x * %g - (z + %g) * %g) - %g, 0)^2",
                            " + Max(Fabs(y) - %g, 0)^2 + (x * %g + (z + %g) * %g)^2)"),
                     Cos(dip), -zc, Sin(dip), width / 2, length / 2, Sin(dip), -zc, Cos(dip));
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = h_fault;
Field[2].SizeMax = h_far;
Field[2].DistMin = 0;
Field[2].DistMax = 700;
// Distance to the reservoir (in z) near the fault.
Field[3] = Box;
Field[3].VIn = h_reservoir;
Field[3].VOut = h_far;
Field[3].XMin = -200; Field[3].XMax = 200;
Field[3].YMin = -W; Field[3].YMax = W;
Field[3].ZMin = zr; Field[3].ZMax = zo;
Field[3].Thickness = 600;
Field[4] = Min;
Field[4].FieldsList = {2, 3};
Background Field = 4;
Mesh.CharacteristicLengthExtendFromBoundary = 0;
Mesh.CharacteristicLengthFromPoints = 0;
Mesh.CharacteristicLengthFromCurvature = 0;
