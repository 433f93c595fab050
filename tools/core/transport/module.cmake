skybake_add_core_module(NAME transport DEPS skybake_atmosphere skybake_optics skybake_io TBB::tbb glm::glm)
