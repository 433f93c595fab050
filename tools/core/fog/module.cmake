# GT7 global fog: the depth model, the reference fog renders, the fit, the LUTs and the evaluator
# (docs/fog.md). Above transport (it renders view segments) and lut (GT7 mappings, packing).
skybake_add_core_module(NAME fog DEPS skybake_transport skybake_lut skybake_color skybake_atmosphere skybake_spectrum skybake_io Eigen3::Eigen TBB::tbb glm::glm)
