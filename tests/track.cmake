# The tracker on images it was not tuned on: widened renders (three adjacent
# tags turned 35 deg, up to 70 deg oblique, motion blur, defocus, vignetting,
# JPEG, tagStandard41h12) against plain libapriltag corners.
kincal_test(e2e_track_render_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/track_render_test.cc
  DEPS kincal_bundle_synthetic kincal_bundle kincal_vision kincal_synth)

# Refined tag corners keep the tag's size (no inward or outward bias).
kincal_test(e2e_corner_scale_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/corner_scale_test.cc
  DEPS kincal_vision kincal_synth)

# The tracker on POV-Ray renders (a renderer we did not write; skipped
# without povray): refined corners and gated tips against plain libapriltag.
kincal_test(e2e_povray_render_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/povray_render_test.cc
  DEPS kincal_bundle_synthetic kincal_vision kincal_synth)
