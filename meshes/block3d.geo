// A 2 m x 1 m x 0.5 m block for the 3D contact scene (scenes/block3d.toml).
// OpenCASCADE numbers the faces of a box x-, x+, y-, y+, z-, z+.
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 2, 1, 0.5};
Physical Surface("left") = {1};
Physical Surface("right") = {2};
Physical Surface("front") = {3};
Physical Surface("back") = {4};
Physical Surface("bottom") = {5};
Physical Surface("top") = {6};
Physical Volume("block") = {1};
Mesh.CharacteristicLengthMax = 0.25;
