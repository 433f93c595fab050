skybake_add_core_module(NAME optics DEPS skybake_io)
# Mie numerics (docs/mie.md, "Performance and determinism"): complex arithmetic without the C99
# Annex G inf/nan recovery (-fcx-fortran-rules keeps range-safe division and is several times
# faster), no contraction into fused multiply-adds (results do not depend on the instruction set
# the angular kernel runs with), and -O3 for the kernels' vectorisation in every build type
# (-Wno-psabi: GCC notes that 64-byte vector values change the ABI between targets; the kernels
# pass none between functions).
set(_mie_numeric_sources mie_sphere.cpp mie_angular.cpp polydisperse.cpp phase_fit.cpp mie_table.cpp)
list(TRANSFORM _mie_numeric_sources PREPEND ${CMAKE_CURRENT_LIST_DIR}/)
# clang 14 (the sanitizer and fuzz build, docs/developing.md) has no -fcx-fortran-rules: it keeps
# Annex G's checked complex division there, slower but within the tests' bounds.
set(_cx_rules "$<$<CXX_COMPILER_ID:GNU>:-fcx-fortran-rules>")
set_source_files_properties(${_mie_numeric_sources} PROPERTIES COMPILE_OPTIONS "${_cx_rules};-ffp-contract=off")
set_source_files_properties(${CMAKE_CURRENT_LIST_DIR}/mie_angular.cpp
  PROPERTIES COMPILE_OPTIONS "${_cx_rules};-ffp-contract=off;-O3;-Wno-psabi")
