"""The contact use cases of W. K. Lau (2023) on a simulated Kinova Gen3 (needs ``mujoco``).

W. K. Lau, "Exploiting contact constraints in robotic manipulation tasks", R&D project report,
Hochschule Bonn-Rhein-Sieg, 2023, lets the environment carry part of a task: a gripper slides on a
table before grasping, a pen draws on it, an elbow rests on a support. Here the same tasks run in
closed loop at 1 kHz, with this package's solver inside the controller:

- :mod:`.robot_interface`: what a control loop reads (joint state) and writes (torques) each cycle;
- :mod:`.mujoco_plant`: the MuJoCo plant, compiled from the same URDF as the controller's chain;
- :mod:`.controller`: the report's cascaded P controller (pose error -> twist -> ``beta``),
  z released in contact, joint friction handled by the friction-aware solve;
- :mod:`.use_cases`: the phases of the grasp and writing tasks and the loop that runs them;
- :mod:`.elbow`: the resting-elbow task, with the support left to the plant or stated as a segment
  constraint;
- :mod:`.dual_arm`: a dual-arm Gen3 on a torso (a kinematic tree), one hand resting on a table
  while the other slides, the tree solver against the arms solved as separate chains
  (:mod:`.dual_arm_report`: ``--case dual-arm``);
- :mod:`.metrics`: effort and accuracy numbers of a run (the report's Tables 6.1-6.3);
- :mod:`.model_error`: the plant's inertias and joint friction perturbed (seeded), for the
  model-error runs;
- :mod:`.surfaces`: the scene's surfaces as the solver's point contacts (``vs.Contact``), used by
  the "after" variants in place of the hand-made table forces and shares (:mod:`.contact_report`:
  the before / after tables, two resting points, the table surfaces);
- :mod:`.report`: runs everything and writes tables and figures
  (``python -m vereshchagin_experiments reproduce --case contact``), with :mod:`.lau2023` (the
  published numbers), :mod:`.report_notes` (setup, gains, differences from the report),
  :mod:`.report_figures` and :mod:`.report_model_error`.

Joints are counted from 0 in every table and figure, as in the report.

Units are SI (m, rad, s, N, N m); poses and twists are in the robot's base frame, z up, gravity
``[0, 0, -9.81]`` m/s^2.
"""
