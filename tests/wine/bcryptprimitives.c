/* Test-only stand-in for Windows' bcryptprimitives.dll, for running our win64
 * binaries under Debian bookworm's Wine 8.0, which lacks that DLL.
 *
 * Rust's standard library (>= 1.78) imports ProcessPrng from bcryptprimitives.dll,
 * present on every Windows 10/11 (Rust's minimum). Wine gained it in 9.x. This
 * shim forwards to RtlGenRandom (advapi32 SystemFunction036), which Wine 8 has.
 * It is placed beside the DLL under test in the test's win64-only copy of an FMU
 * (the Windows loader searches the application's folder first); it is never
 * packed into dist/*.fmu. Built by tests/test_win64.py with x86_64-w64-mingw32-gcc.
 */
#include <windows.h>

BOOLEAN WINAPI SystemFunction036(PVOID buffer, ULONG length);

__declspec(dllexport) BOOL WINAPI ProcessPrng(PBYTE data, SIZE_T size)
{
    while (size > 0) {
        ULONG chunk = size > 0x40000000 ? 0x40000000 : (ULONG)size;
        if (!SystemFunction036(data, chunk))
            return FALSE;
        data += chunk;
        size -= chunk;
    }
    return TRUE;
}
