skybake_add_test_suite(NAME noise DEPS skybake_noise skybake_lut skybake_io TBB::tbb)
