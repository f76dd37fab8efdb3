# cmake -DTHREE_DIR=<the npm package three> -DVIEWER=<view3d.js> -DOUT=<file.cpp> -P EmbedView3d.cmake
# Writes view3d_assets.hpp's definitions: each file as raw-string pieces under 64 KiB (what
# -Wpedantic allows a literal), three's empty when THREE_DIR holds no build of it.

function(sonarbench_embed_pieces var file)
  file(READ "${file}" text)
  string(TOLOWER "${text}" lower)
  foreach(bad "</script" "<!--" ")sbjs\"")
    string(FIND "${lower}" "${bad}" at)
    if(NOT at EQUAL -1)
      message(FATAL_ERROR "${file} holds '${bad}', which cannot sit inside report.html's <script>")
    endif()
  endforeach()
  string(LENGTH "${text}" length)
  set(pieces "")
  set(start 0)
  while(start LESS length)
    string(SUBSTRING "${text}" ${start} 60000 piece)
    string(APPEND pieces "    R\"sbjs(${piece})sbjs\",\n")
    math(EXPR start "${start} + 60000")
  endwhile()
  set(${var} "{\n${pieces}    nullptr}" PARENT_SCOPE)
endfunction()

set(core "${THREE_DIR}/build/three.core.min.js")
set(module "${THREE_DIR}/build/three.module.min.js")
set(controls "${THREE_DIR}/examples/jsm/controls/OrbitControls.js")
set(version "")
set(empty "{nullptr}")
set(core_pieces ${empty})
set(module_pieces ${empty})
set(controls_pieces ${empty})
if(EXISTS "${core}" AND EXISTS "${module}" AND EXISTS "${controls}")
  file(READ "${THREE_DIR}/package.json" package)
  string(JSON version GET "${package}" version)
  sonarbench_embed_pieces(core_pieces "${core}")
  sonarbench_embed_pieces(module_pieces "${module}")
  sonarbench_embed_pieces(controls_pieces "${controls}")
endif()
sonarbench_embed_pieces(viewer_pieces "${VIEWER}")

file(WRITE "${OUT}.tmp" "// Written by cmake/EmbedView3d.cmake from ${THREE_DIR} and ${VIEWER}.
#include \"view3d_assets.hpp\"

namespace sonarbench::sim::view3d_assets {

const char* const kThreeVersion = \"${version}\";
const char* const kThreeCore[] = ${core_pieces};
const char* const kThreeModule[] = ${module_pieces};
const char* const kOrbitControls[] = ${controls_pieces};
const char* const kViewer[] = ${viewer_pieces};

}  // namespace sonarbench::sim::view3d_assets
")
file(COPY_FILE "${OUT}.tmp" "${OUT}" ONLY_IF_DIFFERENT)
file(REMOVE "${OUT}.tmp")
