skybake_add_test_suite(NAME io DEPS skybake_io)
