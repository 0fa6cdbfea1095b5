"""Applications: the ``eyestereo sim`` commands, ``make demo``, the child-process job and step runner."""
