# docs/LAB.md as a test: every command block on its rehearsal stand-ins
# (rendered images as cameras, fake robot controllers on loopback), the
# rehearsal end to end, and the refusals a lab meets first.
kincal_test(e2e_lab_procedure_test
  SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/lab_procedure_test.cc
  DEPS kincal_data kincal_camcal kincal_calib kincal_vision kincal_synth
       nlohmann_json::nlohmann_json)
if(TARGET e2e_lab_procedure_test)
  add_dependencies(e2e_lab_procedure_test kincal)
endif()
