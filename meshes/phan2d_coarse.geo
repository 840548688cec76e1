// meshes/phan2d.geo's crack and plate with the sizes near the crack 8 times
// larger (0.08 m along it, 0.032 m at the tips): the coarsest level of the
// study of Phan et al.'s frictional slip (studies/phan.toml), whose
// mesh.refine = 3 has phan2d.geo's sizes along the crack.
L = 40;
theta = 70 * Pi / 180;
scale = 8;
Include "sneddon2d.geo";
