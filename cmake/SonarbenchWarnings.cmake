# The one place that sets warnings and sanitizers for sonarbench's own targets.
function(sonarbench_set_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow)
  if(SONARBENCH_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
  if(SONARBENCH_SANITIZE)
    target_compile_options(${target} PRIVATE -fsanitize=address,undefined -fno-omit-frame-pointer
                                             -fno-sanitize-recover=undefined)
    target_link_options(${target} PRIVATE -fsanitize=address,undefined)
  endif()
endfunction()
