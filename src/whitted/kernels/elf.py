"""The symbol table of an ELF object file: what Numba's cached machine code defines and what it
needs from elsewhere, read without parsing its LLVM bitcode (kernels/cache_load.py) and
without LLVM at all (kernels/native.py checks every needed name before linking)."""

from __future__ import annotations

import struct

ELF_MAGIC = b"\x7fELF"
SHT_SYMTAB = 2
SHN_UNDEF = 0
SHN_ABS, SHN_COMMON = 0xFFF1, 0xFFF2
SHN_LORESERVE = 0xFF00
STB_GLOBAL, STB_WEAK = 1, 2


def elf_symbols(obj: bytes) -> tuple[set[str], set[str]] | None:
    """(defined, undefined) of an ELF64 little-endian object file: the global and weak
    symbols it defines (functions and data, common symbols such as Numba's environment
    pointers included: the names the JIT linker can resolve in it), and the names it needs
    from elsewhere. None when ``obj`` is not such a file."""
    if obj[:4] != ELF_MAGIC or obj[4] != 2 or obj[5] != 1:  # ELFCLASS64, ELFDATA2LSB
        return None
    (shoff,) = struct.unpack_from("<Q", obj, 0x28)
    shentsize, shnum = struct.unpack_from("<HH", obj, 0x3A)
    sections = [struct.unpack_from("<IIQQQQIIQQ", obj, shoff + i * shentsize)
                for i in range(shnum)]
    defined: set[str] = set()
    undefined: set[str] = set()
    for _name, kind, _flags, _addr, offset, size, link, _info, _align, entsize in sections:
        if kind != SHT_SYMTAB or entsize == 0:
            continue
        strings = sections[link][4]
        for at in range(offset + entsize, offset + size, entsize):  # entry 0 is the null one
            st_name, st_info, _other, st_shndx = struct.unpack_from("<IBBH", obj, at)
            if not st_name:
                continue
            if st_shndx == SHN_UNDEF:
                into = undefined
            elif ((st_info >> 4) in (STB_GLOBAL, STB_WEAK)
                  and (st_shndx < SHN_LORESERVE or st_shndx in (SHN_ABS, SHN_COMMON))):
                into = defined
            else:
                continue
            end = obj.index(b"\0", strings + st_name)
            into.add(obj[strings + st_name:end].decode())
    return defined, undefined
