skybake_add_core_module(NAME lut DEPS skybake_color skybake_spectrum skybake_io TBB::tbb)
