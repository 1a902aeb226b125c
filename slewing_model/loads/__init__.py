"""Loads from aero-elastic codes: OpenFAST output files and the bearing loads in them.

* :mod:`.openfast` -- reads OpenFAST/FAST text and binary output files;
* :mod:`.aeroelastic` -- the pitch or yaw bearing's loads in SI, in the bearing's frame.
"""
