# End-to-end tests of the cameras on the flange (rig.yaml mount: flange,
# format v3): rendered flange sessions, the bundle's robot at fresh poses and
# a hidden backlash named from the images.
kincal_test(e2e_flange_bundle_test
  SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/flange_bundle_test.cc
  DEPS nlohmann_json::nlohmann_json)
if(TARGET e2e_flange_bundle_test)
  add_dependencies(e2e_flange_bundle_test kincal)
endif()
