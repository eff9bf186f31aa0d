# Capture timings: recorder throughput (1280x1024 PNG stereo pairs), folder
# replay rate, pixel conversions.
kincal_bench(capture_bench
  SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/capture_bench.cc
  DEPS kincal_capture)
