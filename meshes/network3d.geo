// The mesh of scenes/network3d.toml: a block of 1 km x 1 km x 600 m
// (x, y in [-500, 500] m, z in [-1600, -1000] m, z up) cut by three
// fractures that meet inside it: "f1", 400 m down dip by 600 m along strike,
// striking along y and dipping 60 degrees towards +x, centred at
// (0, 0, -1300) m; "f2", the vertical plane y = 0 over x in [-250, 250],
// z in [-1450, -1150], crossing f1 along a dipping line (an X); "f3", the
// vertical plane x = 200 over y in [0, 250], the same depths, ending on f2
// (a T). Every edge of a fracture that meets no other lies inside the rock.
// Sizes: 30 m on the fractures, growing to 150 m in the far field.
SetFactory("OpenCASCADE");
W = 500; zb = -1600; zt = -1000; zc = -1300;
width = 400; length = 600; dip = Pi / 3;
Box(1) = {-W, -W, zb, 2 * W, 2 * W, zt - zb};
Rectangle(10) = {-width / 2, -length / 2, 0, width, length};
Rotate {{0, 1, 0}, {0, 0, 0}, dip} { Surface{10}; }
Translate {0, 0, zc} { Surface{10}; }
Rectangle(11) = {-250, zc - 150, 0, 500, 300};
Rotate {{1, 0, 0}, {0, 0, 0}, Pi / 2} { Surface{11}; }
Rectangle(12) = {0, zc - 150, 0, 250, 300};
Rotate {{1, 0, 0}, {0, 0, 0}, Pi / 2} { Surface{12}; }
Rotate {{0, 0, 1}, {0, 0, 0}, Pi / 2} { Surface{12}; }
Translate {200, 0, 0} { Surface{12}; }
BooleanFragments{ Volume{1}; Delete; }{ Surface{10, 11, 12}; Delete; }
e = 1e-3;
hx = width / 2 * Cos(dip) + e; hz = width / 2 * Sin(dip) + e;
Physical Volume("rock") = Volume{:};
Physical Surface("f1") = {Surface In BoundingBox{-hx, -length / 2 - e, zc - hz, hx, length / 2 + e, zc + hz}};
Physical Surface("f2") = {Surface In BoundingBox{-250 - e, -e, zc - 150 - e, 250 + e, e, zc + 150 + e}};
Physical Surface("f3") = {Surface In BoundingBox{200 - e, -e, zc - 150 - e, 200 + e, 250 + e, zc + 150 + e}};
Physical Surface("left") = {Surface In BoundingBox{-W - e, -W - e, zb - e, -W + e, W + e, zt + e}};
Physical Surface("right") = {Surface In BoundingBox{W - e, -W - e, zb - e, W + e, W + e, zt + e}};
Physical Surface("front") = {Surface In BoundingBox{-W - e, -W - e, zb - e, W + e, -W + e, zt + e}};
Physical Surface("back") = {Surface In BoundingBox{-W - e, W - e, zb - e, W + e, W + e, zt + e}};
Physical Surface("bottom") = {Surface In BoundingBox{-W - e, -W - e, zb - e, W + e, W + e, zb + e}};
Physical Surface("top") = {Surface In BoundingBox{-W - e, -W - e, zt - e, W + e, W + e, zt + e}};
Field[1] = Distance;
Field[1].SurfacesList = {Surface In BoundingBox{-W + 1, -W + 1, zb + 1, W - 1, W - 1, zt - 1}};
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = 30;
Field[2].SizeMax = 150;
Field[2].DistMin = 0;
Field[2].DistMax = 400;
Background Field = 2;
Mesh.CharacteristicLengthExtendFromBoundary = 0;
Mesh.CharacteristicLengthFromPoints = 0;
Mesh.CharacteristicLengthFromCurvature = 0;
