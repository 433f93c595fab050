skybake_add_test_suite(NAME transport DEPS skybake_transport skybake_lut skybake_atmosphere skybake_optics skybake_io glm::glm)
