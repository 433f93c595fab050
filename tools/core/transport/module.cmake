skybake_add_core_module(NAME transport DEPS skybake_lut skybake_color skybake_atmosphere skybake_spectrum skybake_optics skybake_io TBB::tbb glm::glm)
