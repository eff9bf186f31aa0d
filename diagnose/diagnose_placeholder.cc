// Placeholder translation unit; replaced by the diagnosis code.
namespace kincal {}
