"""The robot: its plant from the model file with the scenario's variants (``plant``), the
Mitsubishi RV-M1's paper kinematics (``rvm1``), the ``mass_xF`` variant (``mass_scaling``) and
whether the arm reaches its targets (``reachability``)."""
