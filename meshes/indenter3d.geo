// A quarter of an elastic block (x, y in [0, 2], z in [-2, 0]) for a rigid
// sphere of radius 1 indenting its top (scenes/indenter3d.toml): the
// sphere's lowest point touches the top at the origin. Refined towards the
// contact.
SetFactory("OpenCASCADE");
Box(1) = {0, 0, -2, 2, 2, 2};
Physical Surface("top") = {6};
Physical Surface("symmetry_x") = {1};
Physical Surface("symmetry_y") = {3};
Physical Surface("base") = {5};
Physical Volume("block") = {1};
// Element size 0.004 within 0.12 of the first contact, 0.4 far away.
Field[1] = MathEval;
Field[1].F = "Sqrt(x^2 + y^2 + z^2)";
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = 0.004;
Field[2].SizeMax = 0.4;
Field[2].DistMin = 0.12;
Field[2].DistMax = 1.5;
Background Field = 2;
Mesh.CharacteristicLengthExtendFromBoundary = 0;
Mesh.CharacteristicLengthFromPoints = 0;
