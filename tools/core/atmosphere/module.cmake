skybake_add_core_module(NAME atmosphere DEPS skybake_io)
