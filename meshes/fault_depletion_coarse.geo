// meshes/fault_depletion.geo's displaced fault with every size 8 times
// larger (8 m at the reservoir's corners on the fault, 32 m along it) in a
// square four times wider (64 km): the coarsest level of the study of
// Jansen and Meulenbroek's slip (studies/jansen_meulenbroek.toml), whose
// mesh.refine = 3 has fault_depletion.geo's sizes. The wider square takes
// the boundaries' share of the error (0.40 % in l2 with W = 8000 m, 0.23 %
// with 32000 m, both at the sizes of refine = 3) below the finest level's.
W = 32000;
scale = 8;
Include "fault_depletion.geo";
