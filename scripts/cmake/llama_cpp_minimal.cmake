# Injected into llama.cpp's own CMake project when scripts/setup.sh builds llama-cpp-python from source
# (CMAKE_PROJECT_llama.cpp_INCLUDE). gift loads only libllama and libggml through ctypes, so the
# "common" helper library (argument parsing, chat templates, HTTP download; llama-cpp-python forces it
# ON) is not built. LLAVA_BUILD=OFF, passed beside this file, drops the multimodal library.
set(LLAMA_BUILD_COMMON OFF CACHE BOOL "gift: llama-cpp-python loads only libllama/libggml" FORCE)
set(LLAMA_BUILD_TESTS OFF CACHE BOOL "" FORCE)
set(LLAMA_BUILD_TOOLS OFF CACHE BOOL "" FORCE)
set(LLAMA_BUILD_EXAMPLES OFF CACHE BOOL "" FORCE)
set(LLAMA_BUILD_SERVER OFF CACHE BOOL "" FORCE)
