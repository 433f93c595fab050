# VALIDATION: the tests over ~20 s on 2 cores, labelled `validation` instead of `unit`
# (cmake/SkybakeHelpers.cmake).
skybake_add_test_suite(NAME fog DEPS skybake_fog skybake_transport skybake_lut skybake_color skybake_atmosphere skybake_optics skybake_spectrum skybake_io TBB::tbb glm::glm
  VALIDATION FogRender.PathAgreesWithOrders)
