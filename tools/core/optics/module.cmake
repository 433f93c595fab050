skybake_add_core_module(NAME optics DEPS skybake_io)
