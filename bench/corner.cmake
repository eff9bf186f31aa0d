# Per-corner error of the tag corner refinement against the rendered truth,
# one rendering effect at a time, on the random holders of target_bench.
kincal_bench(corner_bench SOURCES ${CMAKE_CURRENT_LIST_DIR}/corner_bench.cc
             DEPS kincal_synth kincal_vision)
# Detected corners of a rendered session against its corners.csv.
kincal_bench(session_corners_bench
             SOURCES ${CMAKE_CURRENT_LIST_DIR}/session_corners_bench.cc
             DEPS kincal_synth kincal_vision)
