#pragma once

// What report.html's 3D view embeds, written at build time by cmake/EmbedView3d.cmake: the npm
// package three's files (empty when the build found none) and the view's own script
// (src/view3d.js). Each is a list of pieces, each under 64 KiB, ended by a null pointer.
namespace sonarbench::sim::view3d_assets {

extern const char* const kThreeVersion;     ///< "" without three.js
extern const char* const kThreeCore[];      ///< build/three.core.min.js
extern const char* const kThreeModule[];    ///< build/three.module.min.js
extern const char* const kOrbitControls[];  ///< examples/jsm/controls/OrbitControls.js
extern const char* const kViewer[];         ///< src/view3d.js

}  // namespace sonarbench::sim::view3d_assets
