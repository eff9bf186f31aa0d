# Bundle solve time vs frames (3 tags x 2 cameras per frame; target: 500
# frames in <= 3 s, about linear in frames).
kincal_bench(bundle_bench SOURCES ${CMAKE_CURRENT_LIST_DIR}/bundle_bench.cc
             DEPS kincal_bundle kincal_bundle_synthetic kincal_synth)
