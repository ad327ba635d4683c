/* ProcessPrng for wine 8.0 (Debian 12), which has no bcryptprimitives.dll:
 * Rust's standard library imports it on Windows (10 and later have it).
 * Only the wine check of `cargo xtask fmu-check` uses this shim, placed
 * beside the C driver; the FMU does not ship it. RtlGenRandom is
 * advapi32's SystemFunction036. */
#include <windows.h>
#define SystemFunction036 NTAPI SystemFunction036
#include <ntsecapi.h>
#undef SystemFunction036

__declspec(dllexport) BOOL WINAPI ProcessPrng(PBYTE data, SIZE_T len) {
    while (len > 0) {
        ULONG n = len > 0x10000000 ? 0x10000000 : (ULONG)len;
        if (!RtlGenRandom(data, n)) return FALSE;
        data += n;
        len -= n;
    }
    return TRUE;
}
