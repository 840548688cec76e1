// The regular fracture network of Flemisch et al. (2018), one of their 2D
// benchmarks (docs/verification.md, "The fracture networks of Flemisch et
// al."): six fractures in the unit square, x = 0.5 and y = 0.5 across it,
// x = 0.75 and y = 0.75 from those to the sides, x = 0.625 and y = 0.625
// between them. The built-in kernel needs the points where fractures meet:
// each fracture is a chain of lines through them, one physical group each.
SetFactory("Built-in");
h = 0.1;                  // halved by mesh.refine
Point(1) = {0, 0, 0, h}; Point(2) = {1, 0, 0, h}; Point(3) = {1, 1, 0, h}; Point(4) = {0, 1, 0, h};
Point(5) = {0.5, 0, 0, h}; Point(6) = {1, 0.5, 0, h}; Point(7) = {1, 0.75, 0, h};
Point(8) = {0.75, 1, 0, h}; Point(9) = {0.5, 1, 0, h}; Point(10) = {0, 0.5, 0, h};
Point(11) = {0.5, 0.5, 0, h}; Point(12) = {0.625, 0.5, 0, h}; Point(13) = {0.75, 0.5, 0, h};
Point(14) = {0.5, 0.625, 0, h}; Point(15) = {0.625, 0.625, 0, h}; Point(16) = {0.75, 0.625, 0, h};
Point(17) = {0.5, 0.75, 0, h}; Point(18) = {0.625, 0.75, 0, h}; Point(19) = {0.75, 0.75, 0, h};
Line(1) = {1, 5}; Line(2) = {5, 2}; Line(3) = {2, 6}; Line(4) = {6, 7}; Line(5) = {7, 3};
Line(6) = {3, 8}; Line(7) = {8, 9}; Line(8) = {9, 4}; Line(9) = {4, 10}; Line(10) = {10, 1};
Curve Loop(1) = {1:10}; Plane Surface(1) = {1};
Line(11) = {5, 11}; Line(12) = {11, 14}; Line(13) = {14, 17}; Line(14) = {17, 9};      // x = 0.5
Line(15) = {10, 11}; Line(16) = {11, 12}; Line(17) = {12, 13}; Line(18) = {13, 6};    // y = 0.5
Line(19) = {13, 16}; Line(20) = {16, 19}; Line(21) = {19, 8};                         // x = 0.75
Line(22) = {17, 18}; Line(23) = {18, 19}; Line(24) = {19, 7};                         // y = 0.75
Line(25) = {12, 15}; Line(26) = {15, 18};                                             // x = 0.625
Line(27) = {14, 15}; Line(28) = {15, 16};                                             // y = 0.625
Line{11:28} In Surface{1};
Physical Curve("bottom") = {1, 2}; Physical Curve("right") = {3, 4, 5}; Physical Curve("top") = {6, 7, 8};
Physical Curve("left") = {9, 10};
Physical Curve("f1") = {11:14}; Physical Curve("f2") = {15:18}; Physical Curve("f3") = {19:21};
Physical Curve("f4") = {22:24}; Physical Curve("f5") = {25, 26}; Physical Curve("f6") = {27, 28};
Physical Surface("rock") = {1};
