# End-to-end tests of `kincal diagnose` (run build/bin/kincal): the blind
# suite (hidden effects, null cases) and the command contracts.
kincal_test(e2e_diagnose_blind_test
  SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/diagnose_blind_test.cc
  DEPS kincal_calib nlohmann_json::nlohmann_json)
add_dependencies(e2e_diagnose_blind_test kincal)
# `diagnose model --folds` (k-fold cross-validation of the selection).
kincal_test(e2e_diagnose_folds_test
  SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/diagnose_folds_test.cc
  DEPS kincal_calib nlohmann_json::nlohmann_json)
add_dependencies(e2e_diagnose_folds_test kincal)
