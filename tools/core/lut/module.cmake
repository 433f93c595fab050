skybake_add_core_module(NAME lut DEPS skybake_io)
