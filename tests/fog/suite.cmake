skybake_add_test_suite(NAME fog DEPS skybake_fog skybake_transport skybake_lut skybake_color skybake_atmosphere skybake_optics skybake_spectrum skybake_io TBB::tbb glm::glm)
