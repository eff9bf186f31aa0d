# Tag corner accuracy, tip accuracy against the stereo bound, and tracking
# throughput on rendered 1280x1024 stereo frames.
kincal_bench(vision_bench SOURCES ${CMAKE_CURRENT_LIST_DIR}/vision_bench.cc
             DEPS kincal_synth kincal_vision)
