"""pnpba-batch's --help without argparse's start (10 ms of the command's 22).

The build runs argparse once (``python3 -m pnpba.batch_help FOLDER``, pnpba.batch's own parser)
and keeps its help at the width a pipe or an 80-column terminal gets. ``pnpba-batch --help`` at
that width prints the kept text, byte for byte argparse's; at any other width, or with any other
argument beside it, argparse answers as always. Imports only os and sys."""
import os
import sys

PREBUILT_WIDTH = 78  # argparse's width for 80 columns (it keeps 2 spare)


def help_width():
    """argparse's help width as shutil.get_terminal_size gives it (COLUMNS, else the terminal's,
    else 80; less 2), without importing shutil (and with it bz2 and lzma)."""
    try:
        columns = int(os.environ["COLUMNS"])
    except (KeyError, ValueError):
        columns = 0
    if columns <= 0:
        try:
            columns = os.get_terminal_size(sys.__stdout__.fileno()).columns or 80
        except (AttributeError, ValueError, OSError):
            columns = 80
    return columns - 2


def prebuilt_help_path(folder, width=PREBUILT_WIDTH):
    return os.path.join(folder, f"batch_help_{width}.txt")


def prebuilt_help(argv):
    """The help argparse would print for argv, when argv asks for help alone at the width the
    build kept; else None (and argparse answers)."""
    if argv not in (["-h"], ["--help"]) or help_width() != PREBUILT_WIDTH:
        return None
    try:
        with open(prebuilt_help_path(os.path.dirname(os.path.abspath(__file__))),
                  encoding="utf-8") as f:
            return f.read()
    except OSError:
        return None


def print_prebuilt_help(argv):
    """Prints the kept help where prebuilt_help has it, as argparse prints its own: to stderr
    when there is no stdout, a failed write ignored. True when it did (the command then exits 0,
    as argparse's --help does)."""
    text = prebuilt_help(argv)
    if text is None:
        return False
    try:
        (sys.stdout or sys.stderr).write(text)
    except (AttributeError, OSError):
        pass
    return True


def write_prebuilt_help(folder):
    """Writes argparse's help for pnpba-batch at PREBUILT_WIDTH into folder (the build does)."""
    from pnpba.batch import help_text

    path = prebuilt_help_path(folder)
    with open(path + ".part", "w", encoding="utf-8") as f:
        f.write(help_text(PREBUILT_WIDTH))
    os.replace(path + ".part", path)


if __name__ == "__main__":
    write_prebuilt_help(sys.argv[1])
