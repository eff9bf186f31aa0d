# Camera calibration timings on OpenCV's stereo images (../shared/data).
kincal_bench(camcal_bench
  SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/camcal_bench.cc
  DEPS kincal_camcal kincal_vision)
