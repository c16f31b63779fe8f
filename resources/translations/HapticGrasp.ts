<?xml version="1.0" encoding="utf-8"?>
<!DOCTYPE TS>
<TS version="2.1">
<context>
    <name>HapticGrasp</name>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/init_gui.py" line="19"/>
        <source>Feel, grasp and move parts with a haptic device</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/session.py" line="132"/>
        <source>off</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/session.py" line="134"/>
        <source>error: %s</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/session.py" line="135"/>
        <source>%s, %.1f MB, %d dropped</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/gui.py" line="184"/>
        <source>Cannot use %s: %s</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="229"/>
        <source>Add note</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/gui.py" line="262"/>
        <source>Note for the reviewer:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/gui.py" line="522"/>
        <source>Mark graspable</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/gui.py" line="522"/>
        <source>Unmark graspable</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="11"/>
        <source>n/a (not in the core snapshot)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="14"/>
        <source>Demo script</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="14"/>
        <source>Mouse and keyboard</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="22"/>
        <source>Device:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="22"/>
        <source>State:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="22"/>
        <source>Grasped part:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="22"/>
        <source>Index force:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="22"/>
        <source>Thumb force:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="22"/>
        <source>Grasping force:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="22"/>
        <source>Servo rate:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="22"/>
        <source>Servo time:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="22"/>
        <source>Moves / faults:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="22"/>
        <source>Exact models:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="22"/>
        <source>Sound:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="22"/>
        <source>Recording:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="74"/>
        <source>No SpaceMouse or HID device attached (plug one in, then reopen this panel).</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="77"/>
        <source>%d HID device(s) attached, none a SpaceMouse or matched by a layout in &lt;FreeCAD user data&gt;/HapticGrasp/devices/.</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="145"/>
        <source>Mouse and keyboard: move the mouse to move the hand in the view plane, wheel for depth, hold G to pinch, Esc cancels. Simulated arm: the same keys move the target of a simulated operator who drives the simulated master arm; the grasp feels the arm&apos;s fingertips</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="187"/>
        <source>%s (not attached)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="142"/>
        <source>Input:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="218"/>
        <source>Start</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="221"/>
        <source>Stop</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="231"/>
        <source>A short note for the reviewer, in the recording at this moment, about the part under the hand (N)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="280"/>
        <source>stopped</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="291"/>
        <source>%v / %m parts</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="292"/>
        <source>Cancel</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="314"/>
        <source>building models</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="320"/>
        <source>Building %s (%d of %d)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="322"/>
        <source>Built %d of %d parts</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="331"/>
        <source>Rebuilding %s (swapped in when no part is held)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="365"/>
        <source>(fault: %s)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="373"/>
        <source>(not displayed: input-only device)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="390"/>
        <source>measuring…</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="400"/>
        <source>%d of %d parts</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="400"/>
        <source>%d of %d parts (the others felt as their boxes until built)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="405"/>
        <source>on</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="405"/>
        <source>silent (no audio output ready)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/prefs.py" line="12"/>
        <source>Contact stiffness K_c:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/prefs.py" line="12"/>
        <source>Contact damping B_c:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/prefs.py" line="12"/>
        <source>Grasp stiffness K_g:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/prefs.py" line="12"/>
        <source>Grasp damping B_g:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/prefs.py" line="12"/>
        <source>Grasp hysteresis d_h:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/prefs.py" line="12"/>
        <source>Holding stiffness K_ox:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/prefs.py" line="12"/>
        <source>Holding rotational stiffness K_oe:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/prefs.py" line="38"/>
        <source>Haptic Grasp</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/prefs.py" line="43"/>
        <source>Two fingers: grasp state machine (Maekawa &amp; Hollerbach)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/prefs.py" line="45"/>
        <source>Multi-finger: grasping force kept apart from the resultant (every fingertip the device has)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/prefs.py" line="47"/>
        <source>Grasp method:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/prefs.py" line="48"/>
        <source>Record sessions</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/prefs.py" line="50"/>
        <source>Start records each session for review: &lt;document folder&gt;/&lt;document name&gt;.reviews/&lt;date_time&gt;.mcap (unsaved documents: ~/.local/share/HapticGrasp/reviews/). Nothing in the document changes.</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/prefs.py" line="67"/>
        <source>Defaults</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/prefs.py" line="72"/>
        <source>Read when haptics start.</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/review.py" line="150"/>
        <source>%s: not in the document by that name, matched to %s (the same place in the order)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/review.py" line="157"/>
        <source>%s: not in the document, not shown</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/review.py" line="167"/>
        <source>%s: changed since the recording (%s); its recorded motion is shown on the part as it is now</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/review.py" line="174"/>
        <source>%s: placed elsewhere in the document than in the recording: shown at the recorded %s</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/review.py" line="180"/>
        <source>%s: not in the recording, left where it is</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/review.py" line="207"/>
        <source>hand at (%.0f, %.0f, %.0f) mm</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/review.py" line="258"/>
        <source>%s: an element of a link array whose elements are not shown as objects (Show Element off): not moved by the preview; Apply still sets it</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/review.py" line="341"/>
        <source>%s: its recorded shape cannot be read (%s)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/review_panel.py" line="75"/>
        <source>Another task panel is open: close it before reviewing a recording.</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/review_panel.py" line="69"/>
        <source>Review a recording</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/review_panel.py" line="71"/>
        <source>A haptic session is running: stop it before reviewing a recording.</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/review_panel.py" line="79"/>
        <source>Session recordings (*.mcap)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/review_panel.py" line="113"/>
        <source>Review</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/review_panel.py" line="147"/>
        <source>One frame back</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/review_panel.py" line="149"/>
        <source>Play / pause</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/review_panel.py" line="367"/>
        <source>Play</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/review_panel.py" line="152"/>
        <source>One frame forward</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/review_panel.py" line="158"/>
        <source>Speed:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/review_panel.py" line="165"/>
        <source>Loop</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/review_panel.py" line="176"/>
        <source>Events and notes (click to jump there):</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/review_panel.py" line="184"/>
        <source>note:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/review_panel.py" line="185"/>
        <source>fault:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/review_panel.py" line="197"/>
        <source>Apply the pose at the cursor</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/review_panel.py" line="199"/>
        <source>Set the parts where the recording has them at the cursor (one undo step)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/review_panel.py" line="227"/>
        <source>%.2f s, %d part(s), %d moved</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/review_panel.py" line="230"/>
        <source>Recorded on %s</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/review_panel.py" line="232"/>
        <source>Played back on %s</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/review_panel.py" line="303"/>
        <source>Cannot show %.2f s: %s</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/review_panel.py" line="326"/>
        <source>(device fault)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/review_panel.py" line="329"/>
        <source>holding %s</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/review_panel.py" line="332"/>
        <source>Fingertip forces %s N, grasping force %.2f N</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/review_panel.py" line="360"/>
        <source>Pause</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/review_panel.py" line="406"/>
        <source>Cannot apply the pose: %s</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/review_panel.py" line="411"/>
        <source>Applied the pose at %.2f s to %s (one undo step).</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/review_panel.py" line="415"/>
        <source>The parts already stand where the recording has them at %.2f s: nothing applied.</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="14"/>
        <source>Simulated arm</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="19"/>
        <source>No SpaceMouse / HID</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="64"/>
        <source>SpaceMouse, %s</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="65"/>
        <source>HID layout %s, %s</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="156"/>
        <source>%s (unavailable)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="390"/>
        <source>%.0f Hz (measured)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/prefs.py" line="23"/>
        <source>Finger spring k:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/prefs.py" line="23"/>
        <source>Part spring k_d:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/prefs.py" line="23"/>
        <source>Friction μ:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/prefs.py" line="23"/>
        <source>Torque weight γ1 (0: 1/L²):</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/prefs.py" line="23"/>
        <source>Grasp weight γ2:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/prefs.py" line="23"/>
        <source>Regularisation γ3:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/prefs.py" line="65"/>
        <source>Multi-finger method (SI; the paper's k 800, k_d 800, μ 1)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/prefs.py" line="63"/>
        <source>Two-finger method (SI; the paper&apos;s K_c 130, B_c 100, K_g 1000, B_g 800)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="22"/>
        <source>Period error p99:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="22"/>
        <source>Real time:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="344"/>
        <source>SCHED_FIFO, memory locked</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="344"/>
        <source>SCHED_FIFO, memory not locked</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="348"/>
        <source>refused: the rate may suffer (tool tip, report view)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="351"/>
        <source>not asked for (preferences)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/session.py" line="148"/>
        <source>none: the carried part has no contact shell yet (it passes through)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/session.py" line="150"/>
        <source>no part near</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/session.py" line="156"/>
        <source>interference %.3f mm (%s)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/session.py" line="157"/>
        <source>%.3f mm (%s)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="22"/>
        <source>Clearance:</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/panel.py" line="385"/>
        <source>(contact off: parts pass through)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/prefs.py" line="55"/>
        <source>Carried parts meet the others</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/prefs.py" line="57"/>
        <source>A carried part stops at the other parts and slides along them (exact surfaces), and the hand feels it; the panel shows the clearance. Off: it passes through them.</source>
        <translation type="unfinished"></translation>
    </message>
</context>
<context>
    <name>HapticGrasp_MarkGraspable</name>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/gui.py" line="506"/>
        <source>Mark graspable</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/gui.py" line="507"/>
        <source>Mark the selected parts graspable (or unmark them); once any part is marked, haptics hand in only the marked parts</source>
        <translation type="unfinished"></translation>
    </message>
</context>
<context>
    <name>HapticGrasp_Review</name>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/gui.py" line="563"/>
        <source>Review a recording…</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/gui.py" line="564"/>
        <source>Play a recorded session back on the document&apos;s parts, jump to its events and notes, and apply the pose at any moment (one undo step)</source>
        <translation type="unfinished"></translation>
    </message>
</context>
<context>
    <name>HapticGrasp_SplitSolids</name>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/gui.py" line="537"/>
        <source>Split into solids</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/gui.py" line="538"/>
        <source>Make one object per solid of the selected objects (the originals are hidden), so that each solid can be grasped on its own</source>
        <translation type="unfinished"></translation>
    </message>
</context>
<context>
    <name>HapticGrasp_Start</name>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/gui.py" line="476"/>
        <source>Start haptics</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/gui.py" line="477"/>
        <source>Start the servo loop and grasp parts with the device</source>
        <translation type="unfinished"></translation>
    </message>
</context>
<context>
    <name>HapticGrasp_Stop</name>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/gui.py" line="490"/>
        <source>Stop haptics</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../plugin/freecad/HapticGrasp/gui.py" line="491"/>
        <source>Stop the servo loop</source>
        <translation type="unfinished"></translation>
    </message>
</context>
</TS>
