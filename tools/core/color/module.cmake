skybake_add_core_module(NAME color DEPS skybake_spectrum skybake_io PkgConfig::OCIO)
