"""Joint models: force laws of clearance joints, shared by the models that use them.

* [`contact`][recipdyn.model.joints.contact] -- dry contact-impact of a journal in a bearing: normal
  force laws with hysteresis damping (Hertz, Lankarani-Nikravesh, Hunt-Crossley, Flores, Gonthier),
  the Hertz stiffness of a pin in a hole, Coulomb friction with Ambrósio's dynamic correction, and
  the hydrodynamic short-bearing (Pinkus-Sternlicht / Ocvirk) oil-film forces.
* [`pins`][recipdyn.model.joints.pins] -- the contact-impact joints at the crank pin and the
  crosshead pin: their parameter layout and state, the kinematics, the joints' forces, the
  mechanism's accelerations and the contact events (compiled; the glue joins them with a load).
"""
