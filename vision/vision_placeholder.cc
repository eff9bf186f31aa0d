// Placeholder translation unit; replaced by the tracking code.
namespace kincal {}
