/* The program's entry point, bound to the oldest __libc_start_main (GLIBC_2.2.5).
 *
 * Linked on glibc 2.34 or newer, the C runtime's own entry point (crt1.o) calls
 * __libc_start_main@GLIBC_2.34, so the program does not start on an older system at all. The
 * test host is linked with -nostartfiles and this entry point instead, so that it runs on
 * every x86-64 glibc and can show what the FMU says on a system below its floor. */
#include "../../fmu_src/shim/glibc_compat.h"

__asm__(".symver __libc_start_main,__libc_start_main@GLIBC_2.2.5");
extern int main(int, char **, char **);
extern int __libc_start_main(int (*)(int, char **, char **), int, char **, void (*)(void), void (*)(void),
                             void (*)(void), void *);

__asm__(".text\n"
        ".globl _start\n"
        "_start:\n"
        "    xor %ebp, %ebp\n"
        "    mov %rdx, %r9\n"           /* the dynamic loader's finaliser */
        "    pop %rsi\n"                /* argc */
        "    mov %rsp, %rdx\n"          /* argv */
        "    and $-16, %rsp\n"
        "    push %rax\n"
        "    push %rsp\n"               /* stack end */
        "    xor %r8d, %r8d\n"          /* fini */
        "    xor %ecx, %ecx\n"          /* init */
        "    lea main(%rip), %rdi\n"
        "    call *__libc_start_main@GOTPCREL(%rip)\n"
        "    hlt\n");
