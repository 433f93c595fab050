skybake_add_core_module(NAME transport DEPS skybake_lut skybake_color skybake_atmosphere skybake_spectrum skybake_optics skybake_io TBB::tbb glm::glm)
# The `orders` method's phases, one idea per file (transport/orders/; skybake_add_core_module globs
# the module's own folder only). They are sources of this target, so they get its flags below.
file(GLOB _skybake_orders_src CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/transport/orders/*.cpp)
target_sources(skybake_transport PRIVATE ${_skybake_orders_src})
# AVX2 where the build machine has it (SKYBAKE_SIMD in CMakeLists.txt; the same bytes as SSE2).
target_compile_options(skybake_transport PRIVATE ${SKYBAKE_VECTOR_FLAGS})
# No floating-point traps (the project never enables them): GCC then if-converts a select whose
# arm is arithmetic (ExpF / LogF blends in the render) and vectorises those loops, which it keeps
# scalar under the default -ftrapping-math. Values are unchanged: it permits no reassociation or
# contraction, only computing both arms of a select (docs/developing.md "Vector width": the same
# LUT and fog bytes with and without it).
target_compile_options(skybake_transport PRIVATE -fno-trapping-math)
