/* The public headers compile as strict C99 and link: STYLE.md rule 1. */
#include <wrapsim/wrapsim.h>

int main(void)
{
    ws_world_def d;
    ws_world_def_init(&d);
    ws_world *w = 0;
    int ok = ws_world_create(&d, &w) == WS_OK && ws_version_number() == WS_VERSION_NUMBER;
    ws_world_destroy(w);
    return ok ? 0 : 1;
}
