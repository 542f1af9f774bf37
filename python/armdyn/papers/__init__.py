"""The papers' reproduction, apart from the library: the library (every other ``armdyn``
module) never imports this package (``tests/docs/test_layout.py``).

* :mod:`armdyn.papers.five_dof`: the arms of the five-DOF validation paper
  (``five-dof-light-lifting-arm-validation.txt``), every reconstructed number and the paper's
  published figures (``PAPER``);
* :mod:`armdyn.papers.geared_arm`: the 44-body geared arm of the six-DOF paper
  (``six-dof-arm-topological-projection.txt``);
* :mod:`armdyn.papers.geared_study`: that paper's 1–4-motor study on the geared arm;
* :mod:`armdyn.papers.reproduce`: ``armdyn reproduce``, both papers' tables and figures as a
  Markdown + PNG report.

The old paths (``armdyn.reproduce``, ``armdyn.geared_study``, ``armdyn.scenes.paper``,
``armdyn.scenes.geared_arm``, and ``armdyn.scenes.five_dof_arm`` / ``three_dof_arm`` /
``geared_arm_6dof``) re-export these modules.
"""
