# The lab procedure of docs/LAB.md end to end (simulate -> fake robot ->
# capture --robot-listen -> track --obs -> calibrate).
kincal_test(e2e_lab_procedure_test
  SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/lab_procedure_test.cc
  DEPS kincal_data nlohmann_json::nlohmann_json)
if(TARGET e2e_lab_procedure_test)
  add_dependencies(e2e_lab_procedure_test kincal)
endif()
