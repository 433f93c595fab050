# VALIDATION: the tests over ~20 s on 2 cores (`ctest -R <name>` on a Release build), labelled
# `validation` instead of `unit` (cmake/SkybakeHelpers.cmake).
skybake_add_test_suite(NAME transport DEPS skybake_transport skybake_lut skybake_atmosphere skybake_spectrum skybake_optics skybake_io glm::glm
  VALIDATION
    MethodOrders.HighAtTheDaylightTargetOnTheHazedSky
    MethodOrders.AgainstThePathTracerFromDaylightToTwilight
    MethodOrders.HighWithTheSunOnTheHorizonOnTheClearSky
    MethodOrders.SecondOrderWithTheBasisKernel
    MethodOrders.OrdersConvergeUnderAThickWaterCloud
    MethodOrders.FirstOrderIsTheSingleScattering
    MethodOrders.TableRayStepsConvergeThroughAThickLayer
    MethodOrders.ForwardOnlyLayerLeavesTheSkyAwayFromTheSun
    MethodOrders.SunOnTheHorizonConvergedInTheSunNodes
    MethodOrders.ThickCloudLayerConvergesWithinItsMeasuredError
    Ambient.ThinCloudAureole
    MethodMsApprox.IsotropicSecondOrderMatchesPathTracer
    Stability.MsApproxWithDenseAerosols
    Stability.MsApproxLutInTwilight
    PathTracerStop.ErrorBarsCoverTheSpreadUnderAThinCloud
    MethodOrders.HighAgainstCachedPathReferences)
