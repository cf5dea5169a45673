#include "base/base.h"

const char *ws_status_string(ws_status status)
{
    switch (status) {
    case WS_OK: return "WS_OK: success";
    case WS_ERR_INVALID_ARGUMENT: return "WS_ERR_INVALID_ARGUMENT: a value is out of range or not finite";
    case WS_ERR_UNINITIALIZED_DEF: return "WS_ERR_UNINITIALIZED_DEF: the Def was not filled by its ws_*_def_init()";
    case WS_ERR_STALE_HANDLE: return "WS_ERR_STALE_HANDLE: the id is null, destroyed or from another world";
    case WS_ERR_OUT_OF_MEMORY: return "WS_ERR_OUT_OF_MEMORY: the allocator returned NULL";
    case WS_ERR_NUMERICAL: return "WS_ERR_NUMERICAL: the step produced NaN, inf or runaway energy and was undone, or was refused as unstable";
    case WS_ERR_BAD_MESH: return "WS_ERR_BAD_MESH: the mesh is not closed, consistent and non-degenerate";
    case WS_ERR_IN_USE: return "WS_ERR_IN_USE: the object is still used";
    case WS_ERR_CALLBACK: return "WS_ERR_CALLBACK: a user callback reported failure";
    case WS_ERR_BUFFER_TOO_SMALL: return "WS_ERR_BUFFER_TOO_SMALL: the buffer holds fewer items than there are";
    case WS_ERR_IO: return "WS_ERR_IO: a file could not be read or written";
    case WS_ERR_UNSUPPORTED: return "WS_ERR_UNSUPPORTED: this build lacks the feature";
    case WS_ERR_IN_STEP: return "WS_ERR_IN_STEP: a call that changes the world was made from a callback inside ws_world_step";
    case WS_ERR_FORMAT: return "WS_ERR_FORMAT: the saved state is truncated, corrupted, of a newer format or of another world's structure";
    }
    return "unknown ws_status";
}

int ws_version_number(void)
{
    return WS_VERSION_NUMBER;
}

const char *ws_version_string(void)
{
    return WS_VERSION_STRING;
}

unsigned ws_build_features(void)
{
    unsigned features = 0;
#ifdef WS_HAVE_CCD
    features |= WS_FEATURE_CCD;
#endif
#ifdef WS_HAVE_ZLIB
    features |= WS_FEATURE_ZLIB;
#endif
    return features;
}
