// The mesh of scenes/injection_fault3d.toml: meshes/fault3d.geo's block,
// layers and dipping fault with coarser sizes, 40 m on the fault and in the
// reservoir near it, 250 m in the far field (a run of the scene takes
// minutes, not tens of minutes).
h_fault = 40;
h_reservoir = 40;
h_far = 250;
Include "fault3d.geo";
