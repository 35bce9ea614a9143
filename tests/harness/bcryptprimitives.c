/* A test shim, never shipped in an FMU: `ProcessPrng` of bcryptprimitives.dll for Wine 8.0,
 * which lacks that DLL. Rust's std on Windows draws its random seeds (HashMap keys) from
 * ProcessPrng, which every Windows since 10 has; this answers it with RtlGenRandom
 * (advapi32's SystemFunction036). tests/python/test_win64.py builds it with MinGW and puts it
 * beside the harness executable, where the Windows loader looks first. */
#include <windows.h>

BOOLEAN WINAPI SystemFunction036(PVOID buffer, ULONG length);

__declspec(dllexport) BOOL WINAPI ProcessPrng(PBYTE data, SIZE_T length) {
    while (length > 0) {
        ULONG chunk = length > 0x10000000 ? 0x10000000 : (ULONG)length;
        if (!SystemFunction036(data, chunk)) return FALSE;
        data += chunk;
        length -= chunk;
    }
    return TRUE;
}
