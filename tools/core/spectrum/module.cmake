skybake_add_core_module(NAME spectrum DEPS skybake_io)
