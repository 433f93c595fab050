skybake_add_test_suite(NAME lut DEPS skybake_lut skybake_io TBB::tbb)
