"""Files in and out: reading only regular files within budgets, writing all or nothing, PNG and
image codecs, the errors every reader raises. The lowest layer of core: it knows no face."""
