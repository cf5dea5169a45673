// The public headers compile as C++ (extern "C") and link: STYLE.md rule 1.
#include <wrapsim/wrapsim.h>

int main()
{
    ws_world_def d;
    ws_world_def_init(&d);
    ws_world *w = nullptr;
    bool ok = ws_world_create(&d, &w) == WS_OK && ws_version_number() == WS_VERSION_NUMBER;
    ws_world_destroy(w);
    return ok ? 0 : 1;
}
