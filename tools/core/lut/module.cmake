skybake_add_core_module(NAME lut DEPS skybake_atmosphere skybake_color skybake_spectrum skybake_io TBB::tbb)
