// Placeholder translation unit; replaced by the camera sources.
namespace kincal {}
