// Placeholder translation unit; replaced by the camera model code.
namespace kincal {}
