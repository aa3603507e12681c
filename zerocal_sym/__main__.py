from zerocal_sym.cli import entry

entry()
