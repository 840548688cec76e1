// The crack of Phan, Napier, Gray and Kaplan (2003) (tests/test_phan.py,
// bench/friction.py): meshes/sneddon2d.geo's crack of half-length 1 m, in a
// plate of 80 m (half-side 40 m), turned to 70 degrees from the x axis:
// 20 degrees from the y axis, the axis of the compression.
L = 40;
theta = 70 * Pi / 180;
Include "sneddon2d.geo";
