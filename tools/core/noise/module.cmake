skybake_add_core_module(NAME noise DEPS skybake_io TBB::tbb)
