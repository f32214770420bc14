!> What bulkflow offers instead of an Abaqus keyword it does not simulate: the second half
!> of the message for such a keyword (scene_layout), so a user reading an Abaqus/CAE or
!> CalculiX deck learns what to write instead. '' for a keyword we know nothing about.
module scene_unsupported
  implicit none
  private

  public :: unsupported_hint

contains

  pure function unsupported_hint(name) result(hint)
    character(len=*), intent(in) :: name
    character(len=:), allocatable :: hint

    select case (name)
    case ('STATIC', 'FREQUENCY', 'BUCKLE', 'HEAT TRANSFER', 'COUPLED TEMPERATURE-DISPLACEMENT', 'VISCO', &
         'SOIL', 'MODAL DYNAMIC', 'STEADY STATE DYNAMICS', 'GEOSTATIC', 'COMPLEX FREQUENCY', 'GREEN', &
         'SENSITIVITY', 'UNCOUPLED TEMPERATURE-DISPLACEMENT', 'COUPLED THERMAL-ELECTRIC', 'ELECTROMAGNETIC', &
         'MASS DIFFUSION', 'SUBSTRUCTURE GENERATE', 'MATRIX GENERATE', 'RANDOM RESPONSE', 'RESPONSE SPECTRUM', &
         'DYNAMIC TEMPERATURE-DISPLACEMENT', 'SELECT EIGENMODES', 'CREEP', 'CFD')
       hint = 'bulkflow runs explicit dynamics only: *DYNAMIC, EXPLICIT (quasi-static loading: a slow ' // &
            'amplitude, *FIXED MASS SCALING, *STOP CONDITION)'
    case ('PLASTIC', 'HYPERELASTIC', 'HYPERFOAM', 'VISCOELASTIC', 'CONCRETE DAMAGED PLASTICITY', 'CAP PLASTICITY', &
         'CRUSHABLE FOAM', 'CLAY PLASTICITY', 'CAST IRON PLASTICITY', 'EXPANSION', 'CONDUCTIVITY', 'SPECIFIC HEAT', &
         'DAMPING', 'DAMAGE INITIATION', 'DAMAGE EVOLUTION', 'EOS', 'HYPOELASTIC', 'PORE FLUID EXPANSION', &
         'PERMEABILITY', 'LATENT HEAT', 'USER DEFINED FIELD PROPERTIES', 'CREEP STRAIN RATE CONTROL', 'RATE DEPENDENT', &
         'PLASTIC AXIAL', 'DRUCKER PRAGER CREEP', 'CONCRETE', 'BRITTLE CRACKING', 'JOULE HEAT FRACTION', 'INELASTIC HEAT FRACTION')
       hint = 'not a material option bulkflow has; it offers *ELASTIC, *MOHR COULOMB (+ HARDENING, *TENSION ' // &
            'CUTOFF, *FLOW FUNCTION), *DRUCKER PRAGER and *USER MATERIAL (a VUMAT)'
    case ('SHELL SECTION', 'SHELL GENERAL SECTION', 'BEAM SECTION', 'BEAM GENERAL SECTION', 'MEMBRANE SECTION', &
         'COHESIVE SECTION', 'CONNECTOR SECTION', 'GASKET SECTION', 'SURFACE SECTION', 'MASS', 'ROTARY INERTIA', &
         'SPRING', 'DASHPOT', 'USER ELEMENT', 'UEL PROPERTY', 'EMBEDDED ELEMENT', 'REBAR LAYER', 'FLUID PROPERTY', &
         'SOLID SECTION COMPOSITE', 'INFINITE SECTION', 'TRUSS SECTION', 'ORIENTATION', 'NORMAL', 'TRANSFORM', &
         'SYSTEM', 'HOURGLASS STIFFNESS', 'TRANSVERSE SHEAR STIFFNESS')
       hint = 'bulkflow has continuum elements only (CPE4R, C3D8R, *SOLID SECTION) in global axes'
    case ('CLOAD', 'CFLUX', 'DFLUX', 'DSFLUX', 'FILM', 'SFILM', 'RADIATE', 'FIELD', &
         'CONNECTOR LOAD', 'CONNECTOR MOTION', 'BASE MOTION', 'INERTIA RELIEF', 'PRESSURE STRESS', 'DSECURRENT', &
         'CECHARGE', 'DECHARGE', 'CSLOAD', 'CORRELATION', 'MOTION', 'CHANGE FRICTION', 'MODEL CHANGE')
       hint = 'bulkflow offers gravity (*DLOAD, GRAV), pressure on element surfaces (*DSLOAD, P), prescribed displacements and velocities (*BOUNDARY) ' // &
            'and moving rigid walls (*RIGID BODY + *BOUNDARY on its reference node)'
    case ('EQUATION', 'MPC', 'TIE', 'COUPLING', 'KINEMATIC COUPLING', 'DISTRIBUTING COUPLING', 'KINEMATIC', &
         'DISTRIBUTING', 'CONNECTOR BEHAVIOR', 'SHELL TO SOLID COUPLING', 'CONTACT INTERFERENCE', 'CLEARANCE', &
         'GAP', 'CONTACT DAMPING', 'CONTACT CONTROLS', 'SURFACE SMOOTHING', 'ADJUST')
       hint = 'constraints and tied/node-based contact are not simulated; bulkflow offers *CONTACT PAIR (and ' // &
            'general *CONTACT) of an element surface with an analytic rigid surface, and *RIGID BODY'
    case ('NGEN', 'NCOPY', 'NFILL', 'NMAP', 'ELGEN', 'ELCOPY', 'NODAL THICKNESS', &
         'IMPORT', 'MAP SOLUTION', 'INCLUDE FILE', 'SUBMODEL', 'ELEMENT RESPONSE', 'NODE RESPONSE', 'WAVE')
       hint = 'mesh generation and imports are not read; write the nodes and elements out ' // &
            '(*NODE, *ELEMENT; *NSET/*ELSET, GENERATE)'
    case ('VARIABLE MASS SCALING', 'CONTROLS', 'SOLUTION TECHNIQUE', 'STEADY STATE CRITERIA', 'ADAPTIVE MESH', &
         'ADAPTIVE MESH CONTROLS', 'ADAPTIVE MESH CONSTRAINT', 'EXTREME VALUE', 'MATRIX OUTPUT', 'ELEMENT MATRIX OUTPUT', &
         'SECTION FILE', 'SECTION PRINT', 'RADIATION OUTPUT', 'SURFACE OUTPUT', 'INTEGRATED OUTPUT')
       hint = 'not available; bulkflow offers *FIXED MASS SCALING, *BULK VISCOSITY, *SECTION CONTROLS and ' // &
            '*OUTPUT with *NODE/*ELEMENT/*ENERGY OUTPUT'
    case default
       hint = ''
    end select
  end function unsupported_hint
end module scene_unsupported
