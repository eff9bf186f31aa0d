# Scenes of a simulated session for POV-Ray (a renderer we did not write),
# and the scoring of the tracked tips; bench/povray_session.sh runs them.
kincal_bench(povray_scene SOURCES ${CMAKE_CURRENT_LIST_DIR}/povray_scene.cc
             DEPS kincal_synth kincal_vision)
