!> The scene reader: an Abaqus-syntax input file (with bulkflow's few extensions, see
!> docs/keywords.md) -> a complete, validated `model_t` (docs/solver_interfaces.md §2).
!>
!> Everything is checked here, before the first increment; the first problem found ends
!> the reading with `file:line: what is wrong; expected ...` in `err`. The passes:
!> parts and instances flattened (scene_assembly), keywords and their places (scene_layout), mesh, sets, materials, sections, amplitudes,
!> interactions, surfaces and rigid bodies, initial conditions, steps.
module scene_reader
  use error_report, only: error_t, raise_error
  use keyword_reader, only: keyword_deck_t, read_keyword_file
  use scene_digest, only: digest_deck
  use scene_assembly, only: flatten_assembly
  use scene_idioms, only: rewrite_idioms
  use scene_parameters, only: apply_parameters
  use scene_discrete_rigid, only: rewrite_discrete_rigid
  use model, only: model_t
  use scene_layout, only: scene_layout_t, scan_layout
  use scene_mesh, only: mesh_sources_t, build_mesh, read_nodes
  use scene_geometry, only: check_element_geometry
  use scene_sets, only: build_sets
  use scene_materials, only: build_materials
  use scene_sections, only: build_sections
  use scene_amplitudes, only: build_amplitudes
  use scene_interactions, only: build_interactions
  use scene_surfaces, only: build_surfaces, build_rigid_bodies
  use scene_initial, only: build_initial_conditions
  use scene_steps, only: build_steps
  use scene_mpm, only: is_mpm_scene, check_mpm_keywords, build_mpm, mpm_has_nodes, attach_surface_walls
  implicit none
  private

  public :: read_scene

contains

  !> Parse, build and validate the scene in `path`.
  !> `user_subroutine`: a user's VUMAT is compiled in, so *USER MATERIAL names are not
  !> checked against ours (default .false.: our VUMATs only).
  subroutine read_scene(path, model, err, user_subroutine)
    character(len=*), intent(in) :: path
    type(model_t), intent(out) :: model
    type(error_t), intent(out) :: err
    logical, intent(in), optional :: user_subroutine
    type(keyword_deck_t) :: deck
    type(scene_layout_t) :: layout
    type(mesh_sources_t) :: sources
    logical :: user
    integer :: grid_block

    user = .false.
    if (present(user_subroutine)) user = user_subroutine
    model%input_file = path
    call read_keyword_file(path, deck, err)
    if (err%raised) return
    if (deck%n_blocks == 0) then
       ! file:1 - the place to start writing; a file of comments only says so too
       call raise_error(path, 1, 'the scene is empty (no keyword line); expected Abaqus keywords ' // &
            '(*NODE, *ELEMENT, *MATERIAL, *STEP, ...)', err)
       return
    end if
    ! *PARAMETER: every <name> replaced by its value first, so the digest and every pass see
    ! the deck the parameters mean.
    call apply_parameters(deck, err)
    if (err%raised) return
    call digest_deck(deck, model%digest)
    ! Parts and instances become the flat deck they mean; a flat deck is left as it is.
    call flatten_assembly(deck, err)
    if (err%raised) return
    ! Print requests dropped (noted), model-level *RESTART and general contact restated.
    call rewrite_idioms(deck, model%notes, err)
    if (err%raised) return
    ! R2D2 walls of a *RIGID BODY, ELSET= become the analytic SEGMENTS surfaces they describe.
    call rewrite_discrete_rigid(deck, err)
    if (err%raised) return
    call scan_layout(deck, layout, err)
    if (err%raised) return
    call read_heading(deck, model, err)
    if (err%raised) return
    allocate (model%nsets(0), model%elsets(0))
    ! A material-point scene (*MPM GRID) has no mesh: materials, amplitudes, the MPM keywords
    ! (scene_mpm) and the steps.
    grid_block = is_mpm_scene(deck)
    call check_mpm_keywords(deck, grid_block, err)
    if (err%raised) return
    if (grid_block /= 0) then
       call build_materials(deck, layout, model, user, err)
       if (err%raised) return
       call build_amplitudes(deck, model, err)
       if (err%raised) return
       call build_mpm(deck, layout, grid_block, model, err)
       if (err%raised) return
       ! rigid surfaces as walls: their reference nodes (and sets), interactions, surfaces, bodies
       if (mpm_has_nodes(deck)) call read_nodes(deck, layout, model, err)
       if (.not. err%raised) call build_sets(deck, layout, model, err)
       if (.not. err%raised) call build_interactions(deck, layout, model, err)
       if (.not. err%raised) call build_surfaces(deck, layout, model, err)
       if (.not. err%raised) call build_rigid_bodies(deck, layout, model, err)
       if (err%raised) return
       ! predefined fields on the particles of a material (TEMPERATURE, FIELD only)
       call build_initial_conditions(deck, layout, model, err)
       if (err%raised) return
       call count_user_fields(model)
       call build_steps(deck, layout, model, err)
       if (.not. err%raised) call attach_surface_walls(deck, layout, model, err)
       return
    end if
    call build_mesh(deck, layout, model, sources, err)
    if (err%raised) return
    call build_sets(deck, layout, model, err)
    if (err%raised) return
    call build_materials(deck, layout, model, user, err)
    if (err%raised) return
    call build_sections(deck, layout, sources, model, err)
    if (err%raised) return
    call check_element_geometry(deck, model, sources, err)
    if (err%raised) return
    call build_amplitudes(deck, model, err)
    if (err%raised) return
    call build_interactions(deck, layout, model, err)
    if (err%raised) return
    call build_surfaces(deck, layout, model, err)
    if (err%raised) return
    call build_rigid_bodies(deck, layout, model, err)
    if (err%raised) return
    call build_initial_conditions(deck, layout, model, err)
    if (err%raised) return
    call count_user_fields(model)
    call build_steps(deck, layout, model, err)
  end subroutine read_scene

  !> A user's VUMAT or VUSDFLD receives every field variable the scene defines (nfieldv = the
  !> highest VARIABLE= of *INITIAL CONDITIONS, TYPE=FIELD, or FIELDS= of *USER DEFINED FIELD if
  !> larger), as in Abaqus; our own models with our VUSDFLD keep theirs.
  subroutine count_user_fields(model)
    type(model_t), intent(inout) :: model
    integer :: k, n

    n = 0
    do k = 1, size(model%initial_fields)
       n = max(n, model%initial_fields(k)%variable)
    end do
    do k = 1, model%n_materials
       if (model%materials(k)%user_code .or. model%materials(k)%user_field_code) &
            model%materials(k)%nfieldv = max(model%materials(k)%nfieldv, n)
    end do
  end subroutine count_user_fields

  !> *HEADING: its first data line is the title (one *HEADING at most).
  subroutine read_heading(deck, model, err)
    type(keyword_deck_t), intent(in) :: deck
    type(model_t), intent(inout) :: model
    type(error_t), intent(inout) :: err
    integer :: i, seen

    seen = 0
    do i = 1, deck%n_blocks
       if (deck%blocks(i)%name /= 'HEADING') cycle
       call deck%blocks(i)%check_params([character(len=8) ::], err)
       if (err%raised) return
       if (seen /= 0) then
          call deck%blocks(i)%fail('second *HEADING; expected one *HEADING per scene', err)
          return
       end if
       seen = i
       if (deck%blocks(i)%n_lines > 0) model%heading = deck%blocks(i)%lines(1)%text
    end do
  end subroutine read_heading
end module scene_reader
