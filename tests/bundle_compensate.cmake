# The bundle's robot file back to the robot: render -> bundle -> compensate
# a joint program of fresh poses; the predicted sigma against the true error.
kincal_test(e2e_bundle_compensate_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/bundle_compensate_test.cc
  DEPS kincal_calib nlohmann_json::nlohmann_json)
if(TARGET e2e_bundle_compensate_test)
  add_dependencies(e2e_bundle_compensate_test kincal)
endif()
