skybake_add_core_module(NAME transport DEPS skybake_lut skybake_color skybake_atmosphere skybake_spectrum skybake_optics skybake_io TBB::tbb glm::glm)
# AVX2 where the build machine has it (SKYBAKE_SIMD in CMakeLists.txt; the same bytes as SSE2).
target_compile_options(skybake_transport PRIVATE ${SKYBAKE_VECTOR_FLAGS})
