// A fault plane across a 4 m x 1 m x 2 m box (x in [0, 4], y in [0, 1],
// z in [-1, 1] m), its plane z = 0 the whole cross-section: the 3D channel
// of the conduit fault's tests (tests/test_fault_closure.py,
// test_conduit_fault.py, test_conduit_monolithic.py) and of
// bench/conduit.py --compare closure. The fault is the physical surface
// "crack"; the outer faces "left" (x = 0), "right" (x = 4), "bottom",
// "top" (z) and "sides" (y = 0 and 1); the volume "rock". An unstructured
// mesh of size 0.25 (a later Mesh.CharacteristicLengthMax refines it).
SetFactory("OpenCASCADE");
L = 4; B = 1; H = 1;
Box(1) = {0, 0, -H, L, B, 2 * H};
Rectangle(10) = {0, 0, 0, L, B};
BooleanFragments{ Volume{1}; Delete; }{ Surface{10}; Delete; }
e = 1e-6;
Physical Surface("crack") = {Surface In BoundingBox{-e, -e, -e, L + e, B + e, e}};
Physical Surface("left") = {Surface In BoundingBox{-e, -e, -H - e, e, B + e, H + e}};
Physical Surface("right") = {Surface In BoundingBox{L - e, -e, -H - e, L + e, B + e, H + e}};
Physical Surface("bottom") = {Surface In BoundingBox{-e, -e, -H - e, L + e, B + e, -H + e}};
Physical Surface("top") = {Surface In BoundingBox{-e, -e, H - e, L + e, B + e, H + e}};
Physical Surface("sides") = {Surface In BoundingBox{-e, -e, -H - e, L + e, e, H + e},
                             Surface In BoundingBox{-e, B - e, -H - e, L + e, B + e, H + e}};
Physical Volume("rock") = {Volume{:}};
Mesh.CharacteristicLengthMax = 0.25;
