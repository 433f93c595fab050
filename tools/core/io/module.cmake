skybake_add_core_module(NAME io DEPS
  yaml-cpp CLI11::CLI11 spdlog::spdlog fmt::fmt TBB::tbb OpenEXR::OpenEXR Imath::Imath PkgConfig::XXHASH PkgConfig::PNG)
