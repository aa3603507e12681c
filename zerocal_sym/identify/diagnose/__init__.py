"""The diagnose stage: why a fit is rejected, and which readings move the answer.

The likely causes and their paragraph (:mod:`~.causes`), the verdict in the result (:mod:`~.verdict`),
the deletion diagnostics (:mod:`~.deletions`) and the exact refits without readings (:mod:`~.leave_out`,
with the revisits' shared error :mod:`~.revisit_refits`).  Imports the basics, estimate and check.
"""
