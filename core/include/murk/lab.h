/* murk/lab.h — libmurklab, murk's lab: the commands that measure renders and plugins (`murk bench`,
 * `murk compare`, `murk check`), apart from the renderer. It links libmurk (murk/murk.h); a program that
 * only renders needs neither this header nor this library, and plugins never use either.
 *   cc prog.c $(pkg-config --cflags --libs murk-lab) */
#ifndef MURK_LAB_H
#define MURK_LAB_H

/* The commands, as the murk command runs them: argv holds the arguments after the command's name
 * (argv[0] is the first argument, not "bench"), the return value is the command's exit status, and
 * output and errors go to stdout and stderr as the command's do. */
int murk_lab_bench(int argc, char **argv);   /* murk bench SCENE.yaml [--vary KEY=V1,V2,...]... */
int murk_lab_compare(int argc, char **argv); /* murk compare TEST.exr REFERENCE.exr [...] */
int murk_lab_check(int argc, char **argv);   /* murk check [--seed S] [--quick] PLUGIN... */

#endif
