// The regular fracture network of Berre et al. (2021), "Verification
// benchmarks for single-phase flow in three-dimensional fractured porous
// media", Case 2 (docs/verification.md, "The 3D network of Berre et al."):
// nine fractures in the unit cube, x, y, z = 0.5 across it, 0.75 over
// [0.5, 1]^2 and 0.625 over [0.5, 0.75]^2; the inlet the squares of side
// 0.25 at the origin's three faces, the outlet those of side 0.125 at the
// opposite corner (an inlet per face: a flux is given on a plane).
// OpenCASCADE fragments the cube along them; each group
// is found by its bounding box.
SetFactory("OpenCASCADE");
h = 0.125;                // halved by mesh.refine
Mesh.CharacteristicLengthMax = h;
Box(1) = {0, 0, 0, 1, 1, 1};
// A rectangle normal to axis a (0: x, 1: y, 2: z) at c, spanning [lo, hi]
// in the other two.
Macro Quad
  If (a == 0)
    p1 = newp; Point(p1) = {c, lo, lo}; Point(p1 + 1) = {c, hi, lo}; Point(p1 + 2) = {c, hi, hi}; Point(p1 + 3) = {c, lo, hi};
  ElseIf (a == 1)
    p1 = newp; Point(p1) = {lo, c, lo}; Point(p1 + 1) = {hi, c, lo}; Point(p1 + 2) = {hi, c, hi}; Point(p1 + 3) = {lo, c, hi};
  Else
    p1 = newp; Point(p1) = {lo, lo, c}; Point(p1 + 1) = {hi, lo, c}; Point(p1 + 2) = {hi, hi, c}; Point(p1 + 3) = {lo, hi, c};
  EndIf
  l1 = newl; Line(l1) = {p1, p1 + 1}; Line(l1 + 1) = {p1 + 1, p1 + 2}; Line(l1 + 2) = {p1 + 2, p1 + 3};
  Line(l1 + 3) = {p1 + 3, p1};
  cl = newll; Curve Loop(cl) = {l1, l1 + 1, l1 + 2, l1 + 3};
  s = news; Plane Surface(s) = {cl}; quads[] += s;
Return
quads[] = {};
For a In {0:2}
  c = 0.5; lo = 0; hi = 1; Call Quad;
  c = 0.75; lo = 0.5; hi = 1; Call Quad;
  c = 0.625; lo = 0.5; hi = 0.75; Call Quad;
  c = 0; lo = 0; hi = 0.25; Call Quad;       // the inlet's square on this face
  c = 1; lo = 0.875; hi = 1; Call Quad;      // the outlet's
EndFor
BooleanFragments{ Volume{1}; Delete; }{ Surface{quads[]}; Delete; }
// Each group: the fragments' surfaces inside its rectangle's box.
e = 1e-6;
Physical Surface("inlet_x") = {Surface In BoundingBox{-e, -e, -e, e, 0.25 + e, 0.25 + e}};
Physical Surface("inlet_y") = {Surface In BoundingBox{-e, -e, -e, 0.25 + e, e, 0.25 + e}};
Physical Surface("inlet_z") = {Surface In BoundingBox{-e, -e, -e, 0.25 + e, 0.25 + e, e}};
Physical Surface("outlet") = {Surface In BoundingBox{1 - e, 0.875 - e, 0.875 - e, 1 + e, 1 + e, 1 + e},
                              Surface In BoundingBox{0.875 - e, 1 - e, 0.875 - e, 1 + e, 1 + e, 1 + e},
                              Surface In BoundingBox{0.875 - e, 0.875 - e, 1 - e, 1 + e, 1 + e, 1 + e}};
Physical Surface("x1") = {Surface In BoundingBox{0.5 - e, -e, -e, 0.5 + e, 1 + e, 1 + e}};
Physical Surface("y1") = {Surface In BoundingBox{-e, 0.5 - e, -e, 1 + e, 0.5 + e, 1 + e}};
Physical Surface("z1") = {Surface In BoundingBox{-e, -e, 0.5 - e, 1 + e, 1 + e, 0.5 + e}};
Physical Surface("x2") = {Surface In BoundingBox{0.75 - e, 0.5 - e, 0.5 - e, 0.75 + e, 1 + e, 1 + e}};
Physical Surface("y2") = {Surface In BoundingBox{0.5 - e, 0.75 - e, 0.5 - e, 1 + e, 0.75 + e, 1 + e}};
Physical Surface("z2") = {Surface In BoundingBox{0.5 - e, 0.5 - e, 0.75 - e, 1 + e, 1 + e, 0.75 + e}};
Physical Surface("x3") = {Surface In BoundingBox{0.625 - e, 0.5 - e, 0.5 - e, 0.625 + e, 0.75 + e, 0.75 + e}};
Physical Surface("y3") = {Surface In BoundingBox{0.5 - e, 0.625 - e, 0.5 - e, 0.75 + e, 0.625 + e, 0.75 + e}};
Physical Surface("z3") = {Surface In BoundingBox{0.5 - e, 0.5 - e, 0.625 - e, 0.75 + e, 0.75 + e, 0.625 + e}};
Physical Volume("rock") = Volume{:};
